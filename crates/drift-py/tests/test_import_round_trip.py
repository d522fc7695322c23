"""What any writer writes, every reader reads and re-writes: each of the command line's imports
(`import csv`, `import campaign`, `import ulog`, `import rosbag`) gives recordings that
`Recording.load` reads and `save` writes again, and the copy loads with the same samples, labels,
auxiliary channels and metadata. Needs the CLI binary: GYRODRIFT_BIN (scripts/check-python.sh
sets it); the ULog case needs the shared PX4 sample log."""

from __future__ import annotations

import math
import os
import subprocess
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

import gyrodrift

SHARED = Path(__file__).resolve().parents[4] / "shared"
ULOG = SHARED / "data" / "formats" / "px4-ulog" / "sample_log_small.ulg"


def gyrodrift_cli(*args: str) -> str:
    binary = os.environ.get("GYRODRIFT_BIN")
    if not binary:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    done = subprocess.run([binary, *args], check=True, capture_output=True, text=True)
    return done.stdout


def bench_csv(path: Path, rows: int, start_celsius: float) -> None:
    """One activation at 100 Hz: a gyro with a little noise-like wobble, a slow warm-up."""
    lines = ["t_s,gx_dps,gy_dps,gz_dps,temp_c"]
    for i in range(rows):
        wobble = 0.01 * math.sin(1.7 * i)
        lines.append(f"{i / 100},{0.1 + wobble},{-0.2 - wobble},{0.05 + wobble},{start_celsius + 0.01 * i}")
    path.write_text("\n".join(lines) + "\n")


def import_csv(tmp: Path) -> Path:
    bench_csv(tmp / "bench.csv", 300, 30.0)
    text = (tmp / "bench.csv").read_text().splitlines()
    with_segment = ["segment_id," + text[0]] + ["0," + row for row in text[1:]]
    (tmp / "bench.csv").write_text("\n".join(with_segment) + "\n")
    out = tmp / "csv"
    gyrodrift_cli(
        "import", "csv", str(tmp / "bench.csv"), "-o", str(out), "--rate-hz", "100", "--set-point", "30"
    )
    return out


def import_campaign(tmp: Path) -> Path:
    sheet = ["file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s"]
    for k in range(3):
        bench_csv(tmp / f"a{k}.csv", 200, 30.0)
        sheet.append(f"a{k}.csv,U1,30,1,1,{k + 1},{'' if k == 0 else 60},protocol,{62 * k}")
    (tmp / "sheet.csv").write_text("\n".join(sheet) + "\n")
    out = tmp / "campaign"
    gyrodrift_cli("import", "campaign", str(tmp / "sheet.csv"), "-o", str(out), "--rate-hz", "100")
    return out


def import_ulog(tmp: Path) -> Path:
    if not ULOG.exists():
        pytest.skip(f"{ULOG} is not here")
    out = tmp / "ulog"
    gyrodrift_cli("import", "ulog", str(ULOG), "-o", str(out), "--rate-hz", "1", "--max-gap", "1.5")
    return out


def import_rosbag(tmp: Path) -> Path:
    (tmp / "c.toml").write_text(
        "seed = 5\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30]\n"
        "[protocol]\nintervals_min = [1]\nrepeats = 1\nactivations = 2\nactivation_s = 5\n"
    )
    gyrodrift_cli("simulate", "-q", "--campaign", str(tmp / "c.toml"), "-o", str(tmp / "sim"))
    (recording,) = (tmp / "sim" / "recordings").glob("*.mcap")
    gyrodrift_cli("export", "ros2", str(recording), "-o", str(tmp / "bag.mcap"))
    out = tmp / "rosbag"
    gyrodrift_cli("import", "rosbag", str(tmp / "bag.mcap"), "-o", str(out))
    return out


def assert_same(a: gyrodrift.Recording, b: gyrodrift.Recording) -> None:
    assert b.unit_id == a.unit_id and b.sample_rate_hz == a.sample_rate_hz
    assert b.metadata == a.metadata
    assert len(b.segments) == len(a.segments) > 0
    for x, y in zip(a.segments, b.segments):
        assert y.labels == x.labels and y.power_on_ns == x.power_on_ns
        assert len(y) == len(x) > 0
        np.testing.assert_array_equal(y.since_power_on, x.since_power_on)
        np.testing.assert_array_equal(y.rate_dps, x.rate_dps)
        np.testing.assert_array_equal(y.temperature_raw, x.temperature_raw)
        assert sorted(y.aux) == sorted(x.aux)
        for name, channel in x.aux.items():
            back = y.aux_channel(name)
            assert (back.unit, back.sample_rate_hz) == (channel.unit, channel.sample_rate_hz)
            np.testing.assert_array_equal(back.values, channel.values)


@pytest.mark.parametrize("make", [import_csv, import_campaign, import_ulog, import_rosbag])
def test_every_import_loads_saves_and_loads_back_the_same(
    tmp_path: Path, make: Callable[[Path], Path]
) -> None:
    out = make(tmp_path)
    recordings = sorted((out / "recordings").glob("*.mcap"))
    assert recordings
    for path in recordings:
        loaded = gyrodrift.Recording.load(path)
        copy = tmp_path / f"copy-{path.name}"
        assert loaded.save(copy) > 0
        assert_same(loaded, gyrodrift.Recording.load(copy))
        # And once more from the copy: a saved copy is itself a recording every reader takes.
        again = tmp_path / f"again-{path.name}"
        gyrodrift.Recording.load(copy).save(again)
        assert_same(loaded, gyrodrift.Recording.load(again))
