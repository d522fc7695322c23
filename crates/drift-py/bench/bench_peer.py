"""Rust vs a plain numpy peer (bench/peer.py), side by side in one run on the same data.

    python crates/drift-py/bench/bench_peer.py [--samples 2000000] [--repeats 3] [--campaign default]
    python crates/drift-py/bench/bench_peer.py --tiny   # what CI runs: a correctness check, in seconds

Correction: the deterministic stream of bench_correct.py through every model of
testdata/vectors.json that the peer implements (an extension's extra terms read auxiliary inputs
per sample, which neither the stream nor the peer has: such a model is skipped, saying so) — pure
Rust (`cargo run --release --example correct_throughput`, writing into a buffer allocated once; the
example knows the paper's model and both polynomial baselines only), the binding
(`Corrector.correct_batch`, float32 into `out=` arrays) and the numpy peer. Rust and the binding must
give the same output bits (checksum); the peer the same flags and, for the polynomial baselines, the
same bits, for tables with curves the same values to f32 rounding (drift-core multiplies by cached
reciprocals, the peer divides; tests/test_peer.py checks the same). Only the correction call is
timed on every side; the three run in turn, best of `--repeats` each. Twice: with drift-core's
stuck-sensor threshold (typical data, no reading stuck: the floors apply) and with the vectors' own
threshold of 20 (about 60 % of the readings stuck).

Fitting: a simulated campaign (the paper's default campaign unless `--campaign small`; simulated
once into `--campaign-dir` and reused while its specification and gyrodrift's version stay the
same): the Rust fit (`gyrodrift.fit` on the segments in memory: analyse + fit, rayon on every core)
vs the numpy peer's (same segments, as numpy arrays; one core, as numpy is), whose tables must match
Rust's within 4 float32 ulp with the same curves; then the fit from the files (read + analyse + fit,
`gyrodrift.fit(files)`) vs reading the same files alone (`gyrodrift.Recording.load`).

Prints every figure with its ratio, best of `--repeats`, and the floors: Rust batch correction ≥ 10×
the peer, binding ≥ 50 % of pure Rust, Rust fit ≥ 10× the peer, fit from files < 3× reading them.
Exits 1 if outputs differ; a floor not met is printed, and fails the run only with
`--enforce-floors` (timings on a shared machine are noise at the tiny size).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
from bench_correct import ROOT, checksum, rust, stream, with_stuck_after
from peer import Activation, FitSettings, PeerCorrector, implements, is_calibration
from peer import analyse as peer_analyse
from peer import fit as peer_fit

import gyrodrift

T = TypeVar("T")

SMALL = {
    "units": 1,
    "set_points_celsius": [30.0, 40.0],
    "protocol": {"intervals_min": [1.0, 20.0], "activations": 3, "activation_s": 60.0, "repeats": 2},
    "truth_bias": "aux_rate",
}
DEFAULT = {"truth_bias": "aux_rate"}  # the paper's campaign; ground truth (never read) at 100 Hz


def best_of(repeats: int, run: Callable[[], T]) -> tuple[float, T]:
    """Best wall time of `repeats` runs (seconds) and the last result."""
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = run()
        best = min(best, time.perf_counter() - start)
    assert result is not None
    return best, result


class Table:
    """Rows of (what, figure, ratio, floor) printed as Markdown; remembers wrong outputs (`failed`)
    and floors not met (`below`: timings, which fail the run only with --enforce-floors)."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, str, str, str]] = []
        self.failed: list[str] = []
        self.below: list[str] = []

    def add(self, what: str, figure: str, ratio: str = "", floor: str = "", met: bool = True) -> None:
        self.rows.append((what, figure, ratio, floor + ("" if met else " **not met**")))
        if not met:
            self.below.append(f"{what}: {ratio}, floor {floor}")

    def print(self) -> None:
        print("| what | figure | ratio | floor |")
        print("|---|---:|---:|---|")
        for row in self.rows:
            print("| " + " | ".join(row) + " |")


# (name, stuck-sensor threshold, floors apply): drift-core's default threshold, under which no
# reading of the stream is stuck (typical data: the floors apply), and the test vectors' own (20:
# about 60 % of the readings stuck, the hold path; printed beside).
REGIMES = (("typical", 2000, True), ("60 % stuck", None, False))


# The models examples/correct_throughput.rs corrects (the pure-Rust side of the comparison).
RUST_MODELS = ("modified", "standard", "third_order")
# Largest difference allowed between the peer's and the binding's float32 outputs for tables with
# curves (tests/test_peer.py's ROUNDING_DPS): rounding, far below the noise floor (~1e-3 °/s).
ROUNDING_DPS = 1e-6


def differences(got: tuple[Any, ...], want: tuple[Any, ...], exact: bool) -> str:
    """Where the peer's outputs (corrected, bias, flags) differ from the binding's: "" if nowhere.
    Flags and non-finite values must be identical; finite floats bit for bit if `exact`, else
    within ROUNDING_DPS."""
    problems = []
    for label, g, w in zip(("corrected", "bias", "flags"), got, want):
        g, w = np.asarray(g), np.asarray(w)
        if g.shape != w.shape or g.dtype != w.dtype:
            problems.append(f"{label}: {g.dtype}{g.shape} vs {w.dtype}{w.shape}")
        elif w.dtype != np.float32:
            if not np.array_equal(g, w):
                problems.append(f"{label}: {np.count_nonzero(g != w)} differ")
        else:
            finite = np.isfinite(w)
            same_special = np.array_equal(np.isfinite(g), finite) and np.array_equal(
                g[~finite], w[~finite], equal_nan=True
            )
            if exact:
                bits = g.view(np.uint32)[finite] == w.view(np.uint32)[finite]
                worst = 0.0 if bits.all() else float("inf")
            else:
                worst = float(np.max(np.abs(g[finite].astype(np.float64) - w[finite]), initial=0.0))
            if not same_special or worst > (0.0 if exact else ROUNDING_DPS):
                problems.append(
                    f"{label}: largest difference {worst:.3g} °/s, non-finite alike {same_special}"
                )
    return "; ".join(problems)


def correction(table: Table, samples: int, repeats: int) -> None:
    vectors = json.loads((ROOT / "testdata" / "vectors.json").read_text())
    images = {
        m["name"]: (
            gyrodrift.ModifiedTables if m["kind"] == "modified" else gyrodrift.PolynomialTables
        ).from_image(bytes.fromhex(m["image_hex"]))
        for m in vectors["models"]
        # The paper's tables and the polynomial baselines: what this benchmark compares.
        if m["kind"] in ("modified", "polynomial")
    }
    times, rate, temperature = stream(samples)
    out = (
        np.zeros((samples, 3), np.float32),
        np.zeros((samples, 3), np.float32),
        np.zeros((samples, 3), np.uint16),
    )
    for name, image in images.items():
        if not implements(image):
            print(
                f"skipped: {name} (its extra terms read auxiliary inputs per sample; "
                "neither the stream nor the numpy peer has them)"
            )
    for regime, stuck_after, floors in REGIMES:
        for name, image in images.items():
            if not implements(image):
                continue
            model = image if stuck_after is None else with_stuck_after(image, stuck_after)
            in_rust = name in RUST_MODELS

            # Only the correction is timed, on every side; the checks run on the last outputs.
            def binding(model: Any = model) -> tuple[Any, ...]:
                corrector = gyrodrift.Corrector(model)
                corrector.power_on(temperature[0])
                start = time.perf_counter()
                outputs = corrector.correct_batch(times, rate, temperature, out=out)
                return time.perf_counter() - start, outputs

            def numpy(model: Any = model) -> tuple[Any, ...]:
                corrector = PeerCorrector(model)
                corrector.power_on(temperature[0])
                start = time.perf_counter()
                outputs = corrector.correct_batch(times, rate, temperature)
                return time.perf_counter() - start, outputs

            # Interleaved, one run of each in turn, best of `repeats` each: on a shared machine the
            # load then weighs on the three alike.
            rust_rate, rust_check, binding_s, numpy_s = 0.0, -1, float("inf"), float("inf")
            for _ in range(repeats):
                if in_rust:
                    rate_now, _fresh, rust_check = rust(samples, 1, stuck_after, name)[name]
                    rust_rate = max(rust_rate, rate_now)
                seconds, binding_outputs = binding()
                binding_s = min(binding_s, seconds)
                seconds, numpy_outputs = numpy()
                numpy_s = min(numpy_s, seconds)
            what = f"correct, {name}, {regime}"
            binding_check = checksum(*binding_outputs)
            if in_rust and rust_check != binding_check:
                table.failed.append(
                    f"{what}: the binding's outputs differ from pure Rust's "
                    f"(checksums {rust_check:08x} {binding_check:08x})"
                )
            # Polynomial baselines: the same float32 operations in the same order, bit for bit.
            problems = differences(
                numpy_outputs, binding_outputs, exact=isinstance(model, gyrodrift.PolynomialTables)
            )
            if problems:
                table.failed.append(f"{what}: the peer's outputs differ from the binding's ({problems})")
            ms = samples / 1e6
            binding_rate = samples / binding_s
            numpy_rate = samples / numpy_s
            differ = " (OUTPUTS DIFFER)" if problems else ""
            if in_rust:
                table.add(f"{what}: pure Rust (`correct_block`)", f"{rust_rate / 1e6:.1f} M samples/s")
                binding_vs_rust = binding_rate / rust_rate
                table.add(
                    f"{what}: binding (`correct_batch`, f32, `out=`)",
                    f"{ms / binding_s:.1f} M samples/s",
                    f"{binding_vs_rust:.2f}× pure Rust",
                    "≥ 0.5×" if floors else "",
                    met=binding_vs_rust >= 0.5 or not floors,
                )
                rust_vs_numpy = rust_rate / numpy_rate
                table.add(
                    f"{what}: numpy peer",
                    f"{ms / numpy_s:.2f} M samples/s",
                    f"Rust {rust_vs_numpy:.1f}× peer{differ}",
                    "≥ 10×" if floors else "",
                    met=rust_vs_numpy >= 10 or not floors,
                )
            else:
                # No pure-Rust figure (the example does not know this model): the binding stands in.
                table.add(
                    f"{what}: binding (`correct_batch`, f32, `out=`; no pure-Rust figure)",
                    f"{ms / binding_s:.1f} M samples/s",
                )
                table.add(
                    f"{what}: numpy peer",
                    f"{ms / numpy_s:.2f} M samples/s",
                    f"binding {binding_rate / numpy_rate:.1f}× peer{differ}",
                )


def leaves(tree: Any) -> list[Any]:
    """Every leaf of a JSON tree, in order."""
    if isinstance(tree, dict):
        return [v for k in sorted(tree) for v in leaves(tree[k])]
    if isinstance(tree, list):
        return [v for item in tree for v in leaves(item)]
    return [tree]


# Largest difference allowed between the peer's fitted tables and Rust's, float32 ulp
# (tests/test_peer.py's TABLE_MAX_ULP: numpy's pairwise sums and LAPACK's LU vs Rust's sums in order
# and nalgebra's LU).
TABLE_MAX_ULP = 4


def max_ulp(got: Any, want: Any) -> int:
    """Largest difference in float32 ulp between two tables of the same structure."""
    g, w = leaves(got), leaves(want)
    if len(g) != len(w):
        return 2**31
    a = np.array([float(v) for v in g], np.float32).view(np.int32).astype(np.int64)
    b = np.array([float(v) for v in w], np.float32).view(np.int32).astype(np.int64)
    return int(np.abs(a - b).max(initial=0))


def campaign_folder(name: str, folder: Path) -> Path:
    """`folder` holding the `name` campaign, simulated into it unless it holds this very campaign
    already (same specification, same gyrodrift version: an older simulation may not read back)."""
    spec = SMALL if name == "small" else DEFAULT
    stamp = json.dumps({"spec": spec, "gyrodrift": gyrodrift.__version__}, sort_keys=True)
    stamp_file = folder / "bench_campaign.json"
    if not (folder / "summary.json").exists() or not stamp_file.exists() or stamp_file.read_text() != stamp:
        print(f"simulating the {name} campaign into {folder} ...", flush=True)
        for outputs in ("recordings", "truth"):  # an earlier simulation's files, which may differ
            shutil.rmtree(folder / outputs, ignore_errors=True)
        gyrodrift.simulate(folder, spec)
        stamp_file.write_text(stamp)
    return folder


def fitting(table: Table, folder: Path, repeats: int) -> None:
    files = sorted((folder / "recordings").glob("*.mcap"))
    calibration_files = [
        f
        for f in files
        if (m := gyrodrift.Recording.read_metadata(f)).get("series_kind") == "protocol"
        and float(m["set_point_celsius"]) in (30.0, 40.0)
    ]
    read_s, recordings = best_of(repeats, lambda: [gyrodrift.Recording.load(f) for f in calibration_files])
    segments = [s for r in recordings for s in r.segments]
    samples = sum(len(s) for s in segments)
    activations = [Activation.of(s) for s in segments]  # numpy arrays, outside the timing
    del recordings
    files_s, _ = best_of(repeats, lambda: gyrodrift.fit(files))
    rust_s, rust_units = best_of(repeats, lambda: gyrodrift.fit(segments))
    numpy_s, numpy_units = best_of(repeats, lambda: peer_fit(activations))
    # The analysis alone, one activation after another on one thread on both sides.
    calibration = [(s, a) for s, a in zip(segments, activations) if is_calibration(a)]
    settings = FitSettings()
    rust_analyse_s, _ = best_of(repeats, lambda: [gyrodrift.analyse(s) for s, _ in calibration])
    numpy_analyse_s, _ = best_of(repeats, lambda: [peer_analyse(a, settings) for _, a in calibration])
    rust_ids, numpy_ids = [u.unit_id for u in rust_units], [u.unit_id for u in numpy_units]
    if rust_ids != numpy_ids or not rust_ids:
        table.failed.append(f"fit: units {rust_ids} (Rust) vs {numpy_ids} (peer)")
    if [u.curve_names for u in rust_units] != [u.curve_names for u in numpy_units]:
        table.failed.append("fit: the peer kept other curves")
    worst = max(
        (
            max_ulp(getattr(n, model), json.loads(getattr(r, model).to_json()))
            for r, n in zip(rust_units, numpy_units)
            for model in ("modified", "standard", "third_order")
        ),
        default=0,
    )
    if worst > TABLE_MAX_ULP:
        table.failed.append(f"fit: the peer's tables differ from Rust's by {worst} ulp (> {TABLE_MAX_ULP})")
    ms = samples / 1e6
    table.add(
        f"fit from segments in memory, Rust (analyse + fit; {len(rust_units)} units, {ms:.1f} M samples)",
        f"{rust_s:.2f} s ({ms / rust_s:.1f} M samples/s)",
    )
    table.add(
        "fit from segments in memory, numpy peer",
        f"{numpy_s:.2f} s ({ms / numpy_s:.1f} M samples/s)",
        f"Rust {numpy_s / rust_s:.1f}× peer (tables within {worst} ulp)",
        "≥ 10×",
        met=numpy_s / rust_s >= 10,
    )
    table.add(
        "analysis only, Rust (`gyrodrift.analyse` per activation, one thread)",
        f"{rust_analyse_s:.2f} s ({ms / rust_analyse_s:.1f} M samples/s)",
    )
    table.add(
        "analysis only, numpy peer",
        f"{numpy_analyse_s:.2f} s ({ms / numpy_analyse_s:.1f} M samples/s)",
        f"Rust {numpy_analyse_s / rust_analyse_s:.1f}× peer",
    )
    table.add(
        "read the calibration recordings only (`Recording.load`)",
        f"{read_s:.2f} s ({ms / read_s:.1f} M samples/s)",
    )
    table.add(
        "fit from the files (`gyrodrift.fit(files)`: read + analyse + fit)",
        f"{files_s:.2f} s",
        f"{files_s / read_s:.2f}× read only",
        "< 3×",
        met=files_s / read_s < 3,
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--samples", type=int, default=2_000_000, help="correction stream length")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--campaign", choices=["default", "small"], default="default")
    parser.add_argument("--campaign-dir", type=Path, help="default: target/bench_peer/<campaign>")
    parser.add_argument("--skip-fit", action="store_true")
    parser.add_argument("--skip-correct", action="store_true")
    parser.add_argument(
        "--tiny",
        action="store_true",
        help="CI's size, a check that it runs and agrees: --samples 20000 --repeats 1 --campaign small",
    )
    parser.add_argument("--enforce-floors", action="store_true", help="exit 1 if a floor is not met")
    args = parser.parse_args()
    if args.tiny:
        args.samples, args.repeats, args.campaign = 20_000, 1, "small"
    print(
        f"gyrodrift {gyrodrift.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}, "
        f"{os.cpu_count()} CPUs, load average at start {os.getloadavg()[0]:.2f}"
    )
    table = Table()
    if not args.skip_correct:
        print(f"correction: {args.samples:,} samples, best of {args.repeats}", flush=True)
        correction(table, args.samples, args.repeats)
    if not args.skip_fit:
        folder = campaign_folder(
            args.campaign, args.campaign_dir or ROOT / "target" / "bench_peer" / args.campaign
        )
        print(f"fitting: the {args.campaign} campaign in {folder}, best of {args.repeats}", flush=True)
        fitting(table, folder, args.repeats)
    print(f"load average at end {os.getloadavg()[0]:.2f}\n")
    table.print()
    for what in table.below:
        print(f"floor not met{'' if args.enforce_floors else ' (not enforced)'}: {what}")
    for what in table.failed:
        print(f"FAILED: {what}")
    return 1 if table.failed or (args.enforce_floors and table.below) else 0


if __name__ == "__main__":
    sys.exit(main())
