"""Correction throughput from numpy through the binding vs pure Rust, in one run.

    python crates/drift-py/bench/bench_correct.py [--samples 10000000] [--repeats 3]
    python crates/drift-py/bench/bench_correct.py --tiny   # what CI runs: a correctness check, in seconds

Builds the same deterministic synthetic stream as the Rust example `correct_throughput` (root
`examples/`), which this script builds and runs with `cargo run --release`; both sides correct it
with the models of `testdata/vectors.json` the example knows (the paper's model and both polynomial
baselines; the others are skipped, saying so), best of `--repeats`, and must agree on a checksum of
every output bit. Prints samples/s for both and the ratios; exits 1 if a checksum differs or a model
the example should know is missing from its output. The floor (the binding, float32 inputs into
reused `out=` arrays, which is what the Rust reference does: it writes into a buffer it allocated
once, at 50 % of pure Rust or more) is printed, and fails the run only with `--enforce-floors`.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

import gyrodrift

Model = Union[gyrodrift.ModifiedTables, gyrodrift.PolynomialTables]

ROOT = Path(__file__).resolve().parents[3]
FLOOR = 0.5
# The models examples/correct_throughput.rs corrects.
RUST_MODELS = ("modified", "standard", "third_order")


def stream(n: int) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any]]:
    """Mirror of `sample(i)` in examples/correct_throughput.rs (integer formulas, exact in f32)."""
    i = np.arange(n, dtype=np.uint32)
    times = i % np.uint32(150_000)
    rate = np.empty((n, 3), dtype=np.float32)
    temperature = np.empty((n, 3), dtype=np.float32)
    for a in range(3):
        rate[:, a] = (
            ((i * np.uint32(7) + np.uint32(a * 13)) % np.uint32(2001)).astype(np.float32) - np.float32(1000.0)
        ) * np.float32(0.001)
        temperature[:, a] = np.float32(6600.0) + ((i // np.uint32(50 + 10 * a)) % np.uint32(800)).astype(
            np.float32
        )
    return times, rate, temperature


def checksum(corrected: NDArray[Any], bias: NDArray[Any], flags: NDArray[Any]) -> int:
    parts = [corrected.view(np.uint32), bias.view(np.uint32), flags.astype(np.uint32)]
    return int(np.bitwise_xor.reduce(np.concatenate([p.ravel() for p in parts])))


def rust(
    samples: int, repeats: int, stuck_after: int | None = None, model: str = "all"
) -> dict[str, tuple[float, float, int]]:
    """samples/s (reused outputs, fresh outputs) and checksum per model (or of `model` only) from the
    pure-Rust example; `stuck_after` replaces the models' stuck-sensor threshold (see
    `with_stuck_after`)."""
    command = [
        "cargo",
        "run",
        "--quiet",
        "--release",
        "--locked",
        "--example",
        "correct_throughput",
        "--",
        str(samples),
        str(repeats),
        model,
        *([str(stuck_after)] if stuck_after is not None else []),
    ]
    out = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    result = {}
    for line in out.splitlines():
        name, _n, _seconds, rate, fresh_rate, check = line.split()
        result[name] = (float(rate), float(fresh_rate), int(check, 16))
    return result


def with_stuck_after(model: Model, stuck_after: int) -> Model:
    """`model` with another stuck-sensor threshold. The test vectors' models count 20 identical
    temperature readings as stuck (so the vectors reach that path), which holds ~60 % of this
    stream's samples; drift-core's default, 2000, holds none: the typical case."""
    s = model.settings
    return model.with_settings(
        gyrodrift.Settings(
            raw_per_celsius=s.raw_per_celsius,
            raw_at_zero_celsius=s.raw_at_zero_celsius,
            ambient_margin_celsius=s.ambient_margin_celsius,
            rise_margin_celsius=s.rise_margin_celsius,
            stuck_after_samples=stuck_after,
        )
    )


def binding(
    model: gyrodrift.ModifiedTables | gyrodrift.PolynomialTables,
    inputs: tuple[NDArray[Any], NDArray[Any], NDArray[Any]],
    repeats: int,
    reuse: bool,
) -> tuple[float, int]:
    """Best samples/s of correct_batch over `repeats`, and the outputs' checksum. With `reuse`, the
    outputs go into the same preallocated arrays every time (`out=`), as the Rust reference does."""
    times, rate, temperature = inputs
    n = len(times)
    out = (np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32), np.zeros((n, 3), np.uint16))
    best = float("inf")
    outputs = None
    for _ in range(repeats):
        corrector = gyrodrift.Corrector(model)
        corrector.power_on(temperature[0])
        start = time.perf_counter()
        outputs = corrector.correct_batch(times, rate, temperature, out=out if reuse else None)
        best = min(best, time.perf_counter() - start)
    assert outputs is not None
    return n / best, checksum(*outputs)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--tiny", action="store_true", help="CI's size, a check that it runs: --samples 20000 --repeats 1"
    )
    parser.add_argument("--enforce-floors", action="store_true", help="exit 1 if the floor is not met")
    args = parser.parse_args()
    if args.tiny:
        args.samples, args.repeats = 20_000, 1

    vectors = json.loads((ROOT / "testdata" / "vectors.json").read_text())
    models = {
        m["name"]: (
            gyrodrift.ModifiedTables if m["kind"] == "modified" else gyrodrift.PolynomialTables
        ).from_image(bytes.fromhex(m["image_hex"]))
        for m in vectors["models"]
        # The paper's tables and the polynomial baselines: what this benchmark compares.
        if m["kind"] in ("modified", "polynomial")
    }
    print(
        f"gyrodrift {gyrodrift.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}, "
        f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}"
    )
    print(f"{args.samples:,} samples, best of {args.repeats}")
    reference = rust(args.samples, args.repeats)
    failed = False
    for name in RUST_MODELS:
        if name not in reference or name not in models:
            print(f"FAILED: {name} is missing (from the vectors or from the Rust example's output)")
            failed = True
    for name in models:
        if name not in reference:
            print(f"skipped: {name} (the Rust example `correct_throughput` does not correct it)")
    inputs32 = stream(args.samples)
    inputs64 = (inputs32[0], inputs32[1].astype(np.float64), inputs32[2].astype(np.float64))

    variants = [
        ("f32, new arrays", inputs32, False),
        ("f32, out=", inputs32, True),
        ("f64, new arrays", inputs64, False),
        ("f64, out=", inputs64, True),
    ]
    print("Msamples/s (ratio to pure Rust into a reused buffer)")
    print(
        f"{'model':<12} {'pure Rust':>10} {'Rust, fresh':>12}"
        + "".join(f" {label:>20}" for label, _, _ in variants)
    )
    below = False
    for name, model in models.items():
        if name not in reference:
            continue
        rust_rate, rust_fresh, rust_check = reference[name]
        cells, same = [], True
        for _label, inputs, reuse in variants:
            rate, check = binding(model, inputs, args.repeats, reuse)
            same &= check == rust_check
            cells.append(f"{rate / 1e6:>11.1f} ({rate / rust_rate:4.2f})")
            if reuse and inputs is inputs32 and rate / rust_rate < FLOOR:
                enforced = "" if args.enforce_floors else " (not enforced)"
                print(f"{name}: floor not met{enforced}, the binding should reach {FLOOR:.0%} of pure Rust")
                below = True
        print(
            f"{name:<12} {rust_rate / 1e6:>10.1f} {rust_fresh / 1e6:>12.1f}"
            + "".join(f" {c:>20}" for c in cells)
            + ("  same outputs" if same else "  CHECKSUM DIFFERS")
        )
        if not same:
            print(f"FAILED: {name}: the binding's outputs differ from pure Rust's")
        failed |= not same
    return 1 if failed or (args.enforce_floors and below) else 0


if __name__ == "__main__":
    sys.exit(main())
