"""`gyrodrift.distributed`: one task per unit on a 2-worker Dask cluster gives what one process gives."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import gyrodrift
from conftest import SMALL_CAMPAIGN

distributed = pytest.importorskip(
    "dask.distributed", reason="the [distributed] extra (dask) is not installed"
)

import dask.config  # noqa: E402  (after the skip: needs dask)

from gyrodrift import distributed as line  # noqa: E402

# What differs between two runs of the same task: where and how fast it ran.
VOLATILE = {"timings_s", "peak_rss_bytes", "host", "pid"}

UNITS = ["GIU-01", "GIU-02", "GIU-03"]


@pytest.fixture(scope="module")
def units_campaign(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shared small campaign (20-s activations at +30/+40/+33 °C), with three units."""
    out = tmp_path_factory.mktemp("line")
    gyrodrift.simulate(out, {**SMALL_CAMPAIGN, "name": "pytest-line", "units": len(UNITS)})
    return out


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    # WORKER_CONFIG, as `line.local_cluster` spawns the workers: without Dask's malloc trim setting.
    with (
        dask.config.set(line.WORKER_CONFIG),
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


def stable(result: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in result.items() if k not in VOLATILE}


def test_units_are_grouped_from_metadata(units_campaign: Path, tmp_path: Path) -> None:
    units = line.unit_files(units_campaign)
    assert list(units) == UNITS
    for unit_id, files in units.items():
        assert len(files) == 3  # one recording per set point
        assert all(Path(f).name.startswith(unit_id + "_") for f in files)
    assert line.unit_files(units_campaign / "recordings") == units
    with pytest.raises(gyrodrift.FileError, match=r"no \.mcap recordings"):
        line.unit_files(tmp_path)
    with pytest.raises(gyrodrift.RecordingError, match="ground truth"):
        line.unit_files(units_campaign / "truth")  # never read as recordings


def test_the_cluster_gives_what_one_process_gives(units_campaign: Path, client: Any) -> None:
    """Per unit: the same table images, JSON, records and check records as the single-process
    calls on the whole campaign, and as `process_unit` run here; the tasks ran in the workers."""
    results = line.fan_out(client, units_campaign)
    assert [r["unit_id"] for r in results] == UNITS
    assert all(r["error"] is None for r in results), [r["error"] for r in results]

    # Single process, the whole campaign at once, as a user without Dask would do it.
    fitted = {u.unit_id: u for u in gyrodrift.fit(units_campaign)}
    records = gyrodrift.evaluate(units_campaign).records
    for result in results:
        unit = fitted[result["unit_id"]]
        for name in line.MODELS:
            model = getattr(unit, name)
            assert result["tables"][name]["image"] == model.to_image(), (result["unit_id"], name)
            assert result["tables"][name]["json"] == model.to_json(), (result["unit_id"], name)
        assert result["curve_names"] == unit.curve_names and result["notes"] == unit.notes
        assert result["records"] == [r for r in records if r["unit"] == result["unit_id"]]
        assert result["records"]
        validation = [f for f in result["files"] if "_sp+33.0C_" in f]
        assert result["check_files"] == validation
        assert result["check"] == unit.recommended.check(validation)
        assert [r["axis"] for r in result["check"]] == ["X", "Y", "Z"]

    # The same function in this process: equal apart from where and how fast it ran.
    local = [line.process_unit(u, f) for u, f in line.unit_files(units_campaign).items()]
    assert [stable(r) for r in results] == [stable(r) for r in local]

    # Plain data that pickles; run in the workers, not here; memory and time measured there.
    assert pickle.loads(pickle.dumps(results)) == results
    workers = set(client.run(os.getpid).values())
    assert {r["pid"] for r in results} <= workers and len(workers) == 2
    for r in results:
        assert r["peak_rss_bytes"] > 10 * 2**20
        assert r["timings_s"]["total"] >= r["timings_s"]["evaluate"] > 0
    # Spawned under WORKER_CONFIG: glibc's adaptive malloc left alone (unless this process had it set).
    # (os.getenv, read in the worker; os.environ.get would pickle this process's environment)
    trim = client.run(os.getenv, "MALLOC_TRIM_THRESHOLD_")
    assert len(trim) == 2 and set(trim.values()) == {os.environ.get("MALLOC_TRIM_THRESHOLD_")}


def test_a_stored_image_is_checked_in_a_worker(units_campaign: Path, client: Any) -> None:
    unit = gyrodrift.fit(units_campaign)[1]
    files = line.unit_files(units_campaign)[unit.unit_id]
    future = client.submit(line.check_unit, unit.recommended.to_image(), files, max_drift=1.0)
    remote = future.result()
    assert remote["error"] is None
    assert remote["check"] == unit.recommended.check(files, max_drift=1.0)
    paper = client.submit(line.check_unit, unit.modified.to_image(), files, max_drift=1.0).result()
    assert paper["check"] == unit.modified.check(files, max_drift=1.0)
    # The baselines' images too; an image that is neither is an error of the unit, not the line's.
    standard = client.submit(line.check_unit, unit.standard.to_image(), files, max_drift=1.0).result()
    assert standard["check"] == unit.standard.check(files, max_drift=1.0)
    broken = client.submit(line.check_unit, b"not an image", files).result()
    assert broken["check"] == [] and broken["error"].startswith("ImageError")


def test_a_unit_that_cannot_be_fitted_does_not_stop_the_line(units_campaign: Path, client: Any) -> None:
    """No recording at the calibration set points: that unit's result carries the error."""
    results = line.fan_out(client, units_campaign, calibration=[50, 60])
    assert [r["unit_id"] for r in results] == UNITS
    assert all(r["error"] and r["error"].startswith("FitError") for r in results), results
    assert all(r["tables"] == {} and r["records"] == [] for r in results)


def test_importing_gyrodrift_does_not_import_dask() -> None:
    code = (
        "import sys, gyrodrift\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_without_dask_the_error_names_the_extra() -> None:
    code = (
        "import sys\n"
        "sys.modules['dask'] = None  # `import dask` now fails, as without the extra\n"
        "try:\n"
        "    import gyrodrift.distributed\n"
        "except ImportError as error:\n"
        "    print(error)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "pip install 'gyrodrift[distributed]'" in out, out
