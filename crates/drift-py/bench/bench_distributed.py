"""A production line of units on Dask: one process against a LocalCluster of 1 and 2 workers, in one run.

    python crates/drift-py/bench/bench_distributed.py [--units 4] [--repeats 2] [--size medium]
    python crates/drift-py/bench/bench_distributed.py --tiny   # what CI runs: a check, in seconds

Simulates a campaign of `--units` units (once into `--campaign-dir`, reused while its specification
and gyrodrift's version stay the same), then runs `gyrodrift.distributed.process_unit` (fit,
evaluate, check) for every unit four ways, interleaved, best of `--repeats` each:

- one process: a loop over the units in a fresh child process (so its peak memory is its own);
- `distributed.local_cluster(1)` (`LocalCluster(n_workers=1, threads_per_worker=1,
  processes=True)` spawned under `distributed.WORKER_CONFIG`) and `fan_out`;
- the same with 2 workers;
- and 2 workers of a plain `LocalCluster`, whose nannies set Dask's `MALLOC_TRIM_THRESHOLD_=65536`.

Only the work is timed (the loop in the child; `fan_out` with the cluster up and gyrodrift imported
in its workers), not starting processes. Each way starts fresh processes, so a process's peak
resident memory (`distributed.peak_rss_bytes`, reported by the tasks) covers the units it ran; it
is printed beside its peak before the work. The Rust inside each task uses rayon on every core
unless `--rayon-threads` caps it (RAYON_NUM_THREADS in the child and the workers). Prints the wall
times, their ratio to one process, and each process's peak resident memory beside one unit's
recordings.
Exits 1 if the four ways give different results (table images, records, check records).
"""

from __future__ import annotations

import argparse
import importlib
import json
import multiprocessing
import os
import shutil
import sys
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from dask.distributed import Client, LocalCluster

import gyrodrift
from gyrodrift import distributed

ROOT = Path(__file__).resolve().parents[3]

SIZES: dict[str, dict[str, Any]] = {
    # 20-s activations: the test suite's campaign (0.7 M samples per unit).
    "tiny": {
        "set_points_celsius": [30.0, 40.0, 33.0],
        "protocol": {"intervals_min": [1.0, 20.0], "activations": 3, "activation_s": 20.0, "repeats": 2},
    },
    # 2-min activations, 5 per series (7.2 M samples per unit).
    "medium": {
        "set_points_celsius": [30.0, 40.0, 33.0],
        "protocol": {"intervals_min": [1.0, 20.0], "activations": 5, "activation_s": 120.0, "repeats": 2},
    },
    # The paper's campaign (37.8 M samples per unit).
    "paper": {},
}

VOLATILE = {"timings_s", "peak_rss_bytes", "host", "pid"}
MIB = 2**20


def campaign_folder(size: str, units: int, folder: Path) -> Path:
    """`folder` holding the campaign, simulated into it unless it holds this very campaign already."""
    spec = {**SIZES[size], "name": f"bench-line-{size}", "units": units, "truth_bias": "aux_rate"}
    stamp = json.dumps({"spec": spec, "gyrodrift": gyrodrift.__version__}, sort_keys=True)
    stamp_file = folder / "bench_campaign.json"
    if not (folder / "summary.json").exists() or not stamp_file.exists() or stamp_file.read_text() != stamp:
        print(f"simulating {units} units ({size}) into {folder} ...", flush=True)
        for outputs in ("recordings", "truth"):
            shutil.rmtree(folder / outputs, ignore_errors=True)
        gyrodrift.simulate(folder, spec)
        stamp_file.write_text(stamp)
    return folder


# What a way returns: wall seconds of the work, the per-unit results, and each process's peak
# resident memory before the work (gyrodrift and dask imported, nothing read yet), bytes.
Run = tuple[float, list[dict[str, Any]], list[int]]


def serial(units: Mapping[str, list[str]], rayon_threads: int | None) -> Run:
    """The loop over units, in the (child) process that calls it."""
    if rayon_threads:
        os.environ["RAYON_NUM_THREADS"] = str(rayon_threads)
    idle = distributed.peak_rss_bytes()
    start = time.perf_counter()
    results = [distributed.process_unit(unit_id, files) for unit_id, files in units.items()]
    return time.perf_counter() - start, results, [idle]


def one_process(units: Mapping[str, list[str]], rayon_threads: int | None) -> Run:
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        run: Run = pool.apply(serial, (dict(units), rayon_threads))
    return run


def on_cluster(folder: Path, workers: int, rayon_threads: int | None, dask_default: bool = False) -> Run:
    """`fan_out` on a fresh LocalCluster: `distributed.local_cluster` (workers under
    `WORKER_CONFIG`), or with `dask_default` a plain `LocalCluster` (Dask's MALLOC_TRIM_THRESHOLD_)."""
    env = {"RAYON_NUM_THREADS": str(rayon_threads)} if rayon_threads else {}
    before = os.environ.get("MALLOC_TRIM_THRESHOLD_")
    if dask_default:
        cluster = LocalCluster(  # type: ignore[no-untyped-call]
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0", env=env
        )
        # The nannies left the variable in this process's environment too: take it back out, so
        # that the next ways' processes do not inherit it.
        if before is None:
            os.environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    else:
        cluster = distributed.local_cluster(workers, env=env)
    with cluster, Client(cluster) as client:  # type: ignore[no-untyped-call]
        client.run(importlib.import_module, "gyrodrift.distributed")  # imported before the clock starts
        idle = sorted(client.run(distributed.peak_rss_bytes).values())
        # os.getenv, not os.environ.get: that bound method would pickle this process's environment.
        trim = sorted({str(v) for v in client.run(os.getenv, "MALLOC_TRIM_THRESHOLD_").values()})
        print(f"  {workers} worker(s) up, their MALLOC_TRIM_THRESHOLD_: {', '.join(trim)}", flush=True)
        start = time.perf_counter()
        results = distributed.fan_out(client, folder)
        return time.perf_counter() - start, results, idle


def stable(results: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{k: v for k, v in r.items() if k not in VOLATILE} for r in results]


def peak_per_process(results: list[dict[str, Any]]) -> list[int]:
    """The peak resident memory each process reported last (a high-water mark: it only grows), bytes."""
    peaks: dict[int, int] = {}
    for r in results:
        peaks[r["pid"]] = max(peaks.get(r["pid"], 0), r["peak_rss_bytes"])
    return sorted(peaks.values())


def main() -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--units", type=int, default=4)
    parser.add_argument("--size", choices=list(SIZES), default="medium")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument(
        "--rayon-threads", type=int, help="RAYON_NUM_THREADS per process (default: every core)"
    )
    parser.add_argument("--campaign-dir", type=Path, help="default: target/bench_distributed/<size>-<units>")
    parser.add_argument("--tiny", action="store_true", help="CI's size: --units 2 --size tiny --repeats 1")
    args = parser.parse_args()
    if args.tiny:
        args.units, args.size, args.repeats = 2, "tiny", 1
    print(
        f"gyrodrift {gyrodrift.__version__}, dask {__import__('dask').__version__}, Python "
        f"{sys.version.split()[0]}, {os.cpu_count()} CPUs, rayon threads per process "
        f"{args.rayon_threads or 'all'}, load average at start {os.getloadavg()[0]:.2f}"
    )
    folder = campaign_folder(
        args.size,
        args.units,
        args.campaign_dir or ROOT / "target" / "bench_distributed" / f"{args.size}-{args.units}",
    )
    units = distributed.unit_files(folder)
    files = [Path(f) for fs in units.values() for f in fs]
    unit_bytes = max(sum(Path(f).stat().st_size for f in fs) for fs in units.values())
    samples = json.loads((folder / "summary.json").read_text())["samples"]
    print(
        f"{len(units)} units, {len(files)} recordings, {samples / 1e6:.1f} M samples "
        f"({samples / len(units) / 1e6:.1f} M per unit, 3 axes at 1 kHz); one unit's recordings "
        f"{unit_bytes / MIB:.0f} MiB on disk; best of {args.repeats}",
        flush=True,
    )

    ways: dict[str, Callable[[], Run]] = {
        "one process (a loop over units)": lambda: one_process(units, args.rayon_threads),
        "LocalCluster, 1 worker": lambda: on_cluster(folder, 1, args.rayon_threads),
        "LocalCluster, 2 workers": lambda: on_cluster(folder, 2, args.rayon_threads),
        "LocalCluster, 2 workers, Dask's MALLOC_TRIM_THRESHOLD_": lambda: on_cluster(
            folder, 2, args.rayon_threads, dask_default=True
        ),
    }
    best: dict[str, float] = dict.fromkeys(ways, float("inf"))
    peaks: dict[str, list[int]] = {}
    idles: dict[str, list[int]] = {}
    outputs: dict[str, list[dict[str, Any]]] = {}
    for _ in range(args.repeats):
        for name, run in ways.items():  # interleaved: the machine's load weighs on all alike
            seconds, results, idle = run()
            best[name] = min(best[name], seconds)
            peaks[name], idles[name] = peak_per_process(results), idle
            outputs[name] = results
            print(f"  {name}: {seconds:.2f} s", flush=True)
    print(f"load average at end {os.getloadavg()[0]:.2f}\n")

    reference = stable(outputs["one process (a loop over units)"])
    failed = [name for name, results in outputs.items() if stable(results) != reference]
    failed += [f"{r['unit_id']}: {r['error']}" for r in reference if r["error"]]
    baseline = best["one process (a loop over units)"]
    print("| how | wall time | vs one process | peak RSS per process (before the work) |")
    print("|---|---:|---:|---|")
    for name, seconds in best.items():
        memory = ", ".join(f"{p / MIB:.0f} MiB ({i / MIB:.0f})" for p, i in zip(peaks[name], idles[name]))
        print(f"| {name} | {seconds:.2f} s | {baseline / seconds:.2f}× | {memory} |")
    for what in failed:
        print(f"FAILED: results differ or a unit failed: {what}")
    if not failed:
        print("\nthe four ways give the same tables, records and check records for every unit")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
