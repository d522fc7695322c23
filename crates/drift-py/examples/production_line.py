"""A production line of units: fit, evaluate and check every unit of a campaign on Dask, one task per unit.

Simulates a small campaign of three units (20-s activations at +30, +40 and +33 °C), starts a
LocalCluster of two single-threaded worker processes (`distributed.local_cluster`), and runs
`gyrodrift.distributed.fan_out`: each worker reads one unit's recordings by path, fits its tables,
evaluates them on the data the fit did not see, checks the recommended model on the +33 °C recordings
and returns plain data. Prints one row per unit and writes each unit's firmware images. On a real
cluster, connect with `Client("tcp://scheduler:8786")` instead; the workers need gyrodrift installed
and the same files.

Needs the `distributed` extra: pip install "gyrodrift[distributed]".

    python crates/drift-py/examples/production_line.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import gyrodrift

CAMPAIGN = {
    "name": "python-production-line",
    "seed": 3,
    "units": 3,
    "set_points_celsius": [30.0, 40.0, 33.0],
    "protocol": {"intervals_min": [1.0, 20.0], "activations": 3, "activation_s": 20.0, "repeats": 2},
}


def main() -> None:
    try:
        from dask.distributed import Client

        from gyrodrift import distributed
    except ImportError as error:
        print(f"skipped: {error}")
        return

    with tempfile.TemporaryDirectory(prefix="gyrodrift-line-") as tmp:
        folder = Path(tmp)
        summary = gyrodrift.simulate(folder / "campaign", CAMPAIGN)
        print(f"simulated {len(summary['files'])} recordings, {summary['samples'] / 1e6:.1f} M samples")
        for unit_id, files in distributed.unit_files(folder / "campaign").items():
            print(f"  {unit_id}: {', '.join(Path(f).name for f in files)}")

        # LocalCluster(n_workers=2, threads_per_worker=1, processes=True), its workers spawned
        # without Dask's malloc trim setting (distributed.WORKER_CONFIG).
        with (
            distributed.local_cluster(n_workers=2) as cluster,
            Client(cluster) as client,  # type: ignore[no-untyped-call]
        ):
            started = time.perf_counter()
            results = distributed.fan_out(client, folder / "campaign", calibration=[30, 40], validation=[33])
            print(
                f"\n{len(results)} units on {len(client.scheduler_info()['workers'])} workers "
                f"in {time.perf_counter() - started:.1f} s\n"
            )

        print("| unit | +33 °C drift, uncorrected → modified (X, °/s) | check | worker | peak RSS | time |")
        print("|---|---|---|---|---:|---:|")
        for r in results:
            if r["error"]:
                print(f"| {r['unit_id']} | {r['error']} | | | | |")
                continue
            drift = {
                rec["model"]: rec["drift_dps"]
                for rec in r["records"]
                if rec["split"] == "validation" and rec["axis"] == "X"
            }
            passed = "".join(c["axis"] if c["passed"] else "-" for c in r["check"])
            print(
                f"| {r['unit_id']} | {drift['uncorrected']:.4f} → {drift['modified']:.4f} | {passed} | "
                f"pid {r['pid']} | {r['peak_rss_bytes'] / 2**20:.0f} MiB | {r['timings_s']['total']:.1f} s |"
            )
            tables = folder / "tables" / r["unit_id"]
            tables.mkdir(parents=True)
            for name, model in r["tables"].items():
                (tables / f"{name}.bin").write_bytes(model["image"])
        # The images are the firmware's: load one back and correct with it.
        image = gyrodrift.RecommendedTables.load_image(
            folder / "tables" / results[0]["unit_id"] / "recommended.bin"
        )
        print(
            f"\nwrote {len(results) * len(distributed.MODELS)} firmware images; "
            f"{results[0]['unit_id']}'s recommended tables load back: {image.settings.raw_per_celsius} raw/°C"
        )


if __name__ == "__main__":
    main()
