"""A production line of units: fit, evaluate and check every unit of a campaign on Dask distributed.

Each unit is independent of the others, so the work fans out one task per unit. A task gets its
unit's recording files (paths), the set points and the settings as plain values, builds gyrodrift's
objects inside the worker (a `FittedUnit` does not pickle), and returns plain data: the firmware
table images as bytes, their JSON, the report's records, the check's records, timings and the
worker's peak resident memory. Only that unit's recordings are read by the task, one file at a
time (as `gyrodrift.evaluate` reads them), so a worker's memory is bounded by one unit.

    from dask.distributed import Client
    from gyrodrift import distributed

    with distributed.local_cluster(n_workers=2) as cluster, Client(cluster) as client:
        results = distributed.fan_out(client, "out/campaign", calibration=[30, 40], validation=[33])
    # On a cluster: Client("tcp://scheduler:8786"); the workers need gyrodrift and see the files.

Needs the `distributed` extra: `pip install "gyrodrift[distributed]"` (dask[distributed]).
`unit_files` and `process_unit` run without a cluster too (a loop over units, or any other pool).
"""

from __future__ import annotations

import functools
import os
import socket
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Union

try:
    import dask.config
    from dask.distributed import Client, LocalCluster
except ImportError as error:  # pragma: no cover - exercised by a test that hides dask
    raise ImportError(
        "gyrodrift.distributed needs Dask's distributed scheduler, which gyrodrift does not install "
        "by default: pip install 'gyrodrift[distributed]' (installs dask[distributed])"
    ) from error

import gyrodrift

__all__ = [
    "MODELS",
    "WORKER_CONFIG",
    "check_unit",
    "fan_out",
    "local_cluster",
    "peak_rss_bytes",
    "process_unit",
    "unit_files",
]

_Path = Union[str, "os.PathLike[str]"]
_Model = Union[
    "gyrodrift.RecommendedTables",
    "gyrodrift.ModifiedTables",
    "gyrodrift.PolynomialTables",
    "gyrodrift.RelativePolynomialTables",
]

MODELS = ("recommended", "modified", "by_history", "standard", "third_order", "relative")
"""The fitted models a task returns, as `FittedUnit` names them (the CLI's `tables/<unit>/` files);
the first, the recommended model, is the one to deploy and the one `process_unit` checks."""


WORKER_CONFIG: dict[str, Any] = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}
"""Dask configuration for the workers that run gyrodrift's tasks: leave glibc's malloc trim threshold
alone. Dask's nannies set `MALLOC_TRIM_THRESHOLD_=65536` in every worker they spawn (to give memory
back to the system sooner). Setting it also turns off glibc's adaptive mmap threshold (mallopt(3)),
so the fit's and the evaluation's large temporary buffers become fresh mappings, faulted in page by
page, each time they are allocated: the same units then took 1.5–1.9× as long on two workers
(docs/performance.md). Use it
with `dask.config.set(WORKER_CONFIG)` around `LocalCluster(...)` (what `local_cluster` does), or on
a real cluster in the workers' Dask configuration (`distributed.nanny.pre-spawn-environ:
MALLOC_TRIM_THRESHOLD_: null`)."""


def local_cluster(n_workers: int = 2, **kwargs: Any) -> LocalCluster:
    """A `LocalCluster` of `n_workers` single-threaded worker processes, spawned under
    `WORKER_CONFIG`, for the units of one machine; other keywords go to `LocalCluster`
    (`dashboard_address=":0"` unless given: any free port). Use it as a context manager."""
    kwargs.setdefault("threads_per_worker", 1)
    kwargs.setdefault("processes", True)
    kwargs.setdefault("dashboard_address", ":0")
    with dask.config.set(WORKER_CONFIG):
        cluster: LocalCluster = LocalCluster(n_workers=n_workers, **kwargs)  # type: ignore[no-untyped-call]
    return cluster


def peak_rss_bytes() -> int:
    """This process's peak resident memory so far, bytes: on Linux the kernel's high-water mark of
    this process's own memory (`VmHWM` in /proc/self/status), elsewhere `resource.getrusage`'s
    `ru_maxrss` (macOS: bytes; 0 on Windows, which has neither).

    Not `ru_maxrss` on Linux: for a process started by fork and exec, as Dask's nannies and
    multiprocessing's "spawn" start workers, it begins at the resident size of the parent at the
    fork, so a worker spawned from a process holding 2 GB would report 2 GB."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024  # kB
    except OSError:
        pass
    try:
        import resource
    except ImportError:  # pragma: no cover - Windows
        return 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return int(peak if sys.platform == "darwin" else peak * 1024)


def _recordings_folder(campaign_dir: Path) -> Path:
    recordings = campaign_dir / "recordings"
    return recordings if recordings.is_dir() else campaign_dir


def unit_files(campaign_dir: _Path) -> dict[str, list[str]]:
    """The recording files of a campaign folder (its `recordings/`) or of a folder of `.mcap`
    files, grouped by unit: `{unit_id: [path, ...]}`, units and paths sorted. The unit comes from
    each file's metadata record (`Recording.read_metadata`), so no sample is decoded; one file's
    bytes are in memory at a time. Raises `FileError` (no such folder, or no recordings in it) or
    `RecordingError`."""
    folder = _recordings_folder(Path(campaign_dir))
    if not folder.is_dir():
        raise gyrodrift.FileError(f"{folder}: not a folder of recordings")
    files = sorted(folder.glob("*.mcap"))
    if not files:
        raise gyrodrift.FileError(f"{folder}: no .mcap recordings in it")
    units: dict[str, list[str]] = {}
    for path in files:
        unit_id = gyrodrift.Recording.read_metadata(path)["unit_id"]
        units.setdefault(unit_id, []).append(str(path))
    return dict(sorted(units.items()))


def _set_point(metadata: dict[str, str]) -> float | None:
    value = metadata.get("set_point_celsius")
    return None if value is None else float(value)


def _tables(unit: gyrodrift.FittedUnit) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for name in MODELS:
        model: _Model = getattr(unit, name)
        out[name] = {"image": model.to_image(), "json": model.to_json()}
    return out


def process_unit(
    unit_id: str,
    paths: Sequence[_Path],
    *,
    calibration: Sequence[float] = (30.0, 40.0),
    validation: Sequence[float] = (33.0,),
    settings_json: str | None = None,
    held_out_repeats: bool = True,
    max_drift: float = 0.005,
    max_rms: float = 0.02,
    min_removed: float = 0.5,
) -> dict[str, Any]:
    """Fits, evaluates and checks one unit from its recording files: the task one worker runs.

    `gyrodrift.evaluate(paths, ...)` fits the tables on the protocol activations at the
    `calibration` set points and evaluates them on what the fit did not see (the `validation` set
    points, field sessions, and with `held_out_repeats` each repeat against tables refitted
    without it); the recommended model, the one to deploy, is then checked
    (`RecommendedTables.check`, with the limits given) on the unit's recordings at the
    `validation` set points. `settings_json` is
    `FitSettings.to_json()` text (None: the defaults).

    Returns plain data (it pickles, and equals what the same call returns anywhere else, apart
    from `timings_s`, `peak_rss_bytes`, `host` and `pid`): `unit_id`, `files` (the paths read),
    `tables` (`{model: {"image": bytes, "json": str}}` for each of `MODELS`), `curve_names`,
    `notes`, `records` (the report's records, `Evaluation.records`), `check` (one record per axis;
    empty without recordings at the validation set points), `check_files`, `timings_s` (step →
    seconds: `evaluate`, `check`, `total`, and the pipeline's own steps prefixed `pipeline:`),
    `peak_rss_bytes` (the process's peak resident memory when the task ends, `peak_rss_bytes()`:
    in a worker, the largest of every task it has run so far), `host` and `pid`. `error` is None,
    or the text of the gyrodrift error the unit raised (a `FitError` for data the tables cannot be
    fitted from, say), with the results of the steps it did not reach left empty: one bad unit
    does not stop the line.
    """
    started = time.perf_counter()
    files = [str(p) for p in paths]
    result: dict[str, Any] = {
        "unit_id": unit_id,
        "files": files,
        "tables": {},
        "curve_names": [],
        "notes": [],
        "records": [],
        "check": [],
        "check_files": [],
        "timings_s": {},
        "error": None,
    }
    timings: dict[str, float] = result["timings_s"]
    try:
        settings = None if settings_json is None else gyrodrift.FitSettings.from_json(settings_json)
        step = time.perf_counter()
        evaluation = gyrodrift.evaluate(
            files,
            calibration=list(calibration),
            validation=list(validation),
            settings=settings,
            held_out_repeats=held_out_repeats,
        )
        timings["evaluate"] = time.perf_counter() - step
        for name, seconds in evaluation.timings:
            timings[f"pipeline:{name}"] = seconds
        fitted = [u for u in evaluation.fitted if u.unit_id == unit_id]
        if len(fitted) != 1:
            found = [u.unit_id for u in evaluation.fitted]
            raise gyrodrift.InputError(f"`paths` must be unit `{unit_id}`'s recordings, found units {found}")
        unit = fitted[0]
        result["tables"] = _tables(unit)
        result["curve_names"] = unit.curve_names
        result["notes"] = unit.notes
        result["records"] = evaluation.records
        del evaluation

        step = time.perf_counter()
        wanted = {float(v) for v in validation}
        check_files = [p for p in files if _set_point(gyrodrift.Recording.read_metadata(p)) in wanted]
        result["check_files"] = check_files
        if check_files:
            result["check"] = unit.recommended.check(
                check_files, max_drift=max_drift, max_rms=max_rms, min_removed=min_removed, settings=settings
            )
        timings["check"] = time.perf_counter() - step
    except gyrodrift.GyrodriftError as error:
        result["error"] = f"{type(error).__name__}: {error}"
    timings["total"] = time.perf_counter() - started
    return _with_worker(result)


def _with_worker(result: dict[str, Any]) -> dict[str, Any]:
    """`result` with where the task ran and the peak memory of its process."""
    result["peak_rss_bytes"] = peak_rss_bytes()
    result["host"] = socket.gethostname()
    result["pid"] = os.getpid()
    return result


def _model_from_image(image: bytes) -> _Model:
    """The model a firmware image holds, whichever kind it is (the image names its kind; a decoder
    of another kind refuses it with `ImageError`)."""
    kinds: tuple[Any, ...] = (
        gyrodrift.RecommendedTables,
        gyrodrift.ModifiedTables,
        gyrodrift.PolynomialTables,
    )
    for kind in kinds:
        try:
            model: _Model = kind.from_image(image)
            return model
        except gyrodrift.ImageError:
            pass
    return gyrodrift.RelativePolynomialTables.from_image(image)


def check_unit(
    image: bytes,
    paths: Sequence[_Path],
    *,
    max_drift: float = 0.005,
    max_rms: float = 0.02,
    min_removed: float = 0.5,
    settings_json: str | None = None,
) -> dict[str, Any]:
    """Is a stored calibration still valid? One unit's firmware table image (`RecommendedTables`,
    `ModifiedTables` or a baseline's, as `process_unit` returns it or `gyrodrift fit` writes it)
    run over new recordings of that unit, as the model's `check` does: returns `check` (one record per axis),
    `timings_s`, `peak_rss_bytes`, `host`, `pid` and `error` (None or the gyrodrift error's text)."""
    started = time.perf_counter()
    result: dict[str, Any] = {"check": [], "error": None}
    try:
        settings = None if settings_json is None else gyrodrift.FitSettings.from_json(settings_json)
        model = _model_from_image(image)
        result["check"] = model.check(
            [str(p) for p in paths],
            max_drift=max_drift,
            max_rms=max_rms,
            min_removed=min_removed,
            settings=settings,
        )
    except gyrodrift.GyrodriftError as error:
        result["error"] = f"{type(error).__name__}: {error}"
    result["timings_s"] = {"total": time.perf_counter() - started}
    return _with_worker(result)


def fan_out(
    client: Client,
    campaign_dir: _Path,
    *,
    calibration: Sequence[float] = (30.0, 40.0),
    validation: Sequence[float] = (33.0,),
    settings: gyrodrift.FitSettings | None = None,
    held_out_repeats: bool = True,
    max_drift: float = 0.005,
    max_rms: float = 0.02,
    min_removed: float = 0.5,
) -> list[dict[str, Any]]:
    """Runs `process_unit` for every unit of `campaign_dir` on `client`'s workers, one task per
    unit (`client.map`), and gathers the results, in unit order. The files are grouped here
    (`unit_files`, metadata only); the workers read them by path, so they must see the same file
    system (a shared folder on a real cluster). Arguments as `process_unit`'s; `settings` is sent
    as its JSON. A unit that raised a gyrodrift error has it in its result's `error`; anything else
    (a worker lost for good, say) is raised here."""
    units = unit_files(campaign_dir)
    task = functools.partial(
        process_unit,
        calibration=[float(v) for v in calibration],
        validation=[float(v) for v in validation],
        settings_json=None if settings is None else settings.to_json(),
        held_out_repeats=held_out_repeats,
        max_drift=max_drift,
        max_rms=max_rms,
        min_removed=min_removed,
    )
    # pure=False: every call runs (timings and memory are measured afresh), rather than reusing a
    # result the scheduler still holds for the same arguments.
    futures = client.map(task, list(units), list(units.values()), pure=False)
    results: list[dict[str, Any]] = client.gather(futures)  # type: ignore[no-untyped-call]
    return results
