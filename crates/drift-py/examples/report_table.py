"""The report's table from Python: simulate a small campaign, fit, evaluate, print the paper's table.

1 unit; +30 and +40 °C for calibration, +33 °C for validation; series of 5 two-minute activations at
1- and 20-min intervals, 2 repeats. Fits the paper's tables and both baselines, evaluates them on
data the fit did not see (held-out repeats at +30/+40 °C, the +33 °C validation set point), prints
the table (rows model × set point, columns unit × axis, mean drift in °/s), corrects one validation
activation with the fitted tables, and with matplotlib installed (`gyrodrift[plot]`) saves the
report's figures.

    python crates/drift-py/examples/report_table.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import gyrodrift

CAMPAIGN = {
    "name": "python-example",
    "seed": 1,
    "units": 1,
    "set_points_celsius": [30.0, 40.0, 33.0],
    "protocol": {"intervals_min": [1.0, 20.0], "repeats": 2},
}


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="gyrodrift-example-") as tmp:
        folder = Path(tmp)
        started = time.perf_counter()
        summary = gyrodrift.simulate(folder / "campaign", CAMPAIGN)
        print(
            f"simulated {len(summary['files'])} recordings, {summary['samples'] / 1e6:.1f} M samples "
            f"in {time.perf_counter() - started:.1f} s"
        )

        started = time.perf_counter()
        evaluation = gyrodrift.evaluate(folder / "campaign", calibration=[30, 40], validation=[33])
        unit = evaluation.fitted[0]
        print(
            f"fitted {unit.unit_id} ({len(unit.curve_names)} curves: {', '.join(unit.curve_names)}) and "
            f"evaluated {len(evaluation.results)} activations in {time.perf_counter() - started:.1f} s\n"
        )
        print("Mean drift, °/s (max − min of the 1-s low-frequency rate over each activation):\n")
        print(gyrodrift.paper_table(evaluation.records))

        # The fitted tables feed the firmware's corrector directly.
        validation = gyrodrift.Recording.load(
            folder / "campaign" / "recordings" / "GIU-01_sp+33.0C_protocol.mcap"
        )
        segment = validation.segments[-1]
        corrector = gyrodrift.Corrector(unit.modified)
        corrector.power_on(segment.temperature_raw[:20].mean(axis=0))
        corrected, _, _ = corrector.correct_batch(
            segment.since_power_on_ms, segment.rate_dps, segment.temperature_raw.astype(np.float32)
        )
        mean_rate = [float(np.abs(corrected[-1000:, axis].mean())) for axis in range(3)]
        print(
            "last +33 °C activation, |mean corrected rate| over its last second (X, Y, Z): "
            + ", ".join(f"{v:.4f}" for v in mean_rate)
            + " °/s"
        )

        try:
            from gyrodrift import plot
        except ImportError:
            print("matplotlib not installed: figures skipped (pip install 'gyrodrift[plot]')")
            return
        written = plot.save_figures(evaluation, folder / "figures")
        print(f"saved {len(written)} figures: {', '.join(p.name for p in written)}")


if __name__ == "__main__":
    main()
