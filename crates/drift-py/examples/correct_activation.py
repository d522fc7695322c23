"""Correct one synthetic activation with the demonstration models and print the drift before/after.

The models are the demonstration tables shipped with the shared test vectors (synthetic, not
fitted from data). The gyro is synthetic too: a unit at rest switched on at 33 °C, warming by about
3 °C over two minutes, whose bias follows the same kind of law the paper's tables describe (a
switch-on bias plus k·rise). Runs non-interactively:

    python crates/drift-py/examples/correct_activation.py [path/to/vectors.json]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import gyrodrift
from gyrodrift import Flags

DEFAULT_VECTORS = Path(__file__).resolve().parents[3] / "testdata" / "vectors.json"
RATE_HZ = 1000
SECONDS = 120
AMBIENT_CELSIUS = 33.0


Model = gyrodrift.ModifiedTables | gyrodrift.PolynomialTables | gyrodrift.RecommendedTables


def load_models(path: Path) -> dict[str, Model]:
    """The vectors' models, from their firmware images (as the firmware would receive them)."""
    models: dict[str, Model] = {}
    for named in json.loads(path.read_text())["models"]:
        image = bytes.fromhex(named["image_hex"])
        if named["kind"] == "modified":
            models[named["name"]] = gyrodrift.ModifiedTables.from_image(image)
        elif named["kind"] == "recommended":
            models[named["name"]] = gyrodrift.RecommendedTables.from_image(image)
        else:
            models[named["name"]] = gyrodrift.PolynomialTables.from_image(image)
    return models


def unit_like(model: gyrodrift.ModifiedTables) -> tuple[NDArray[Any], NDArray[Any]]:
    """A synthetic unit's bias law, per axis, roughly like the tables': the initial bias at
    AMBIENT_CELSIUS (°/s), and k (°/s/°C) at the first and last point of a middle 30 °C curve."""
    axes = json.loads(model.to_json())["axes"]
    initial = [
        np.interp(
            AMBIENT_CELSIUS,
            [a["ambient_celsius"] for a in axis["ambients"]],
            [a["initial_bias_dps"] for a in axis["ambients"]],
        )
        for axis in axes
    ]
    k = [
        [axis["ambients"][1]["curves"][8]["points"][j]["k_dps_per_celsius"] for j in (0, -1)] for axis in axes
    ]
    return np.array(initial), np.array(k).T


def synthetic_activation(
    initial_bias: NDArray[Any], k_first_last: NDArray[Any], seed: int = 7
) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any], NDArray[Any]]:
    """times (ms), measured rate (°/s), raw temperature, true bias (°/s) of a unit at rest."""
    rng = np.random.default_rng(seed)
    n = RATE_HZ * SECONDS
    times = np.arange(1, n + 1, dtype=np.uint32) * (1000 // RATE_HZ)
    t = times / 1000.0
    rise = np.outer(1.0 - np.exp(-t / 45.0), [3.1, 2.9, 3.3])  # °C per axis
    temperature = np.round((AMBIENT_CELSIUS + rise) * 200.0 + rng.normal(0.0, 1.0, rise.shape))
    # k moves from its first to its last value as the unit warms, 5 % off the tables.
    k_first, k_last = 1.05 * k_first_last
    k = k_first + (k_last - k_first) * rise / rise.max(axis=0)
    true_bias = initial_bias + k * rise
    rate = true_bias + rng.normal(0.0, 0.002, rise.shape)  # at rest: the true rate is zero
    return times, rate, temperature.astype(np.float32), true_bias


def zero_error(output: NDArray[Any], from_s: int, to_s: int) -> float:
    """|mean| over a time window, averaged over the axes: the rate error left at rest."""
    window = output[from_s * RATE_HZ : to_s * RATE_HZ]
    return float(np.abs(window.mean(axis=0)).mean())


def main() -> int:
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_VECTORS
    models = load_models(path)
    modified = models["modified"]
    assert isinstance(modified, gyrodrift.ModifiedTables)
    times, rate, temperature, true_bias = synthetic_activation(*unit_like(modified))
    drift = true_bias - true_bias[0]
    print(
        f"gyrodrift {gyrodrift.__version__}: {len(times)} samples, {SECONDS} s at {RATE_HZ} Hz, "
        f"switch-on at {AMBIENT_CELSIUS} °C, unit at rest"
    )
    print(f"drift since switch-on (true): up to {np.abs(drift).max():.4f} °/s")
    print("zero error = |mean output| of the unit at rest, averaged over the axes, °/s")
    print()
    header = f"{'model':<12} {'first 1 s':>10} {'last 10 s':>10}  flags seen"
    print(header)
    print("-" * len(header))
    first, last = zero_error(rate, 0, 1), zero_error(rate, SECONDS - 10, SECONDS)
    print(f"{'uncorrected':<12} {first:>10.5f} {last:>10.5f}")
    for name, model in models.items():
        corrector = gyrodrift.Corrector(model)
        corrector.power_on(temperature[0])
        corrected, _bias, flags = corrector.correct_batch(times, rate, temperature)
        if not np.isfinite(corrected).all():
            print(f"error: {name} produced non-finite output", file=sys.stderr)
            return 1
        seen = Flags(int(np.bitwise_or.reduce(flags, axis=None)))
        names = ", ".join(f.name or "" for f in Flags if f in seen) or "none"
        first, last = zero_error(corrected, 0, 1), zero_error(corrected, SECONDS - 10, SECONDS)
        print(f"{name:<12} {first:>10.5f} {last:>10.5f}  {names}")
    print()
    print("(A synthetic unit made to resemble the demonstration tables: a usage example, not an")
    print(" evaluation. The evaluation comes with the simulator and the fitter.)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
