"""The numpy peer of the benchmark (bench/peer.py) does the same work as the Rust code: same corrected
rates, biases and flags from the corrector; same analysis and same fitted tables from the fit.

Tolerances (stated in docs/performance.md too):
- correction: flags identical; float32 outputs of the polynomial baselines identical bit for bit
  (both compute the same float32 operations in the same order), of the tables with curves (the
  paper's, keyed by history, warm-started) within ROUNDING_DPS (see there);
- analysis: float32 curves within 2 ulp, float64 initial bias within 1e-12 °/s (numpy's pairwise
  sums vs Rust's sums in order);
- fitted tables: structure, curve names, notes and reference times identical; float32 values within
  4 ulp (identical on this campaign when measured; the margin covers numpy's pairwise sums and
  LAPACK's LU, which may round the last bit differently from Rust's sums in order and nalgebra).
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import Model

_spec = importlib.util.spec_from_file_location(
    "peer", Path(__file__).resolve().parents[1] / "bench" / "peer.py"
)
assert _spec is not None and _spec.loader is not None
peer = importlib.util.module_from_spec(_spec)
sys.modules["peer"] = peer
_spec.loader.exec_module(peer)

TABLE_MAX_ULP = 4


def stream(n: int, switch_on: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A heating activation with every fault the corrector handles: NaN and infinite rates, missing
    temperatures, a stuck sensor (more repeats than `stuck_after_samples`), hours past the last
    reference time, rises below and above the tables' curves."""
    rng = np.random.default_rng(7)
    times = np.arange(n, dtype=np.uint32) * np.uint32(3)  # ms: past the last reference times
    times[n // 2 :] += np.uint32(3_600_000)  # an hour later
    shape = 1.0 - np.exp(-np.arange(n) / (n / 4))
    temperature = (switch_on[None, :] + np.outer(shape, [900.0, 600.0, 1500.0])).round().astype(np.float32)
    temperature[: n // 20] -= np.float32(30.0)  # rise below every curve
    temperature[1000:3500, 1] = temperature[1000, 1]  # stuck sensor on Y
    temperature[rng.integers(0, n, 50), 0] = np.nan  # dropouts on X
    temperature[rng.integers(0, n, 5), 2] = np.inf
    rate = rng.normal(0.0, 0.05, (n, 3)).astype(np.float32)
    rate[rng.integers(0, n, 20), 1] = np.nan
    rate[rng.integers(0, n, 5), 2] = -np.inf
    return times, rate, temperature


# drift-core's per-sample path multiplies by reciprocals it caches per reference-time segment and
# keeps stage-3 knots as point + change (for the Cortex-M4's instruction budget); the peer divides
# and interpolates the textbook way. Both are f32: they agree to rounding, far below the noise
# floor (~1e-3 °/s). Flags, NaN/inf positions and the polynomial baselines stay exact.
ROUNDING_DPS = 1e-6


def same_values(a: np.ndarray, b: np.ndarray, exact: bool) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape
    if a.dtype != np.float32:
        assert np.array_equal(a, b)
        return
    both_nan = np.isnan(a) & np.isnan(b)
    if exact:
        assert np.array_equal(a.view(np.uint32)[~both_nan], b.view(np.uint32)[~both_nan])
        return
    assert np.array_equal(np.isfinite(a), np.isfinite(b))
    finite = np.isfinite(a)
    assert np.array_equal(a[~finite & ~both_nan], b[~finite & ~both_nan])  # same infinities
    assert np.max(np.abs(a[finite].astype(np.float64) - b[finite]), initial=0.0) <= ROUNDING_DPS


POLYNOMIAL = ("standard", "third_order")


@pytest.mark.parametrize("name", ["modified", *POLYNOMIAL, "by_history", "warm_started"])
@pytest.mark.parametrize(
    "switch_on", [(6600.0, 6640.0, 6580.0), (6000.0, 6010.0, 5990.0), (8200.0, 8300.0, 8100.0)]
)
def test_correction_matches_rust(
    models: dict[str, Model], name: str, switch_on: tuple[float, float, float]
) -> None:
    model = models[name]
    on = np.array(switch_on, np.float32)
    times, rate, temperature = stream(20_000, on)
    rust = gyrodrift.Corrector(model)
    numpy = peer.PeerCorrector(model)
    assert rust.power_on(on) == numpy.power_on(on)
    # Two blocks: the second continues the activation (stuck counter, held drift, hints).
    for block in (slice(0, 12_345), slice(12_345, None)):
        got = numpy.correct_batch(times[block], rate[block], temperature[block])
        want = rust.correct_batch(times[block], rate[block], temperature[block])
        for g, w in zip(got, want):
            same_values(g, w, exact=name in POLYNOMIAL)
    # The test exercised what it claims to.
    flags = want[2]
    for flag in (
        "TEMPERATURE_INVALID",
        "RATE_INVALID",
        "RATE_INVALID" if name in POLYNOMIAL else "PAST_LAST_REFERENCE",
        "HISTORY_UNKNOWN" if name in ("by_history", "warm_started") else "RATE_INVALID",
    ):
        assert (flags & gyrodrift.Flags[flag].value).any(), flag


def test_analysis_matches_rust(campaign_dir: Path) -> None:
    recording = gyrodrift.Recording.load(campaign_dir / "recordings" / "GIU-01_sp+30.0C_protocol.mcap")
    for segment in recording.segments[:4]:
        want = gyrodrift.analyse(segment)
        got = peer.analyse(peer.Activation.of(segment), peer.FitSettings())
        np.testing.assert_array_max_ulp(got.drift_dps.T, want.drift_dps, maxulp=2)
        np.testing.assert_array_max_ulp(got.rise_celsius.T, want.rise_celsius, maxulp=2)
        np.testing.assert_allclose(got.initial_bias_dps, want.initial_bias_dps, rtol=0, atol=1e-12)
        assert tuple(got.switch_on_raw.tolist()) == want.switch_on_raw


def values(tables: Any, path: str = "") -> list[tuple[str, Any]]:
    """Every leaf of a JSON tree with its path."""
    if isinstance(tables, dict):
        return [v for k in sorted(tables) for v in values(tables[k], f"{path}.{k}")]
    if isinstance(tables, list):
        return [v for i, item in enumerate(tables) for v in values(item, f"{path}[{i}]")]
    return [(path, tables)]


def assert_tables_match(got: dict[str, Any], want: dict[str, Any]) -> None:
    got_values, want_values = values(got), values(want)
    assert [p for p, _ in got_values] == [p for p, _ in want_values]  # same structure and counts
    exact = [(p, g, w) for (p, g), (_, w) in zip(got_values, want_values) if isinstance(w, int)]
    assert [(p, g) for p, g, _ in exact] == [(p, w) for p, _, w in exact]  # reference times, settings
    floats = [(p, g, w) for (p, g), (_, w) in zip(got_values, want_values) if isinstance(w, float)]
    g = np.array([v for _, v, _ in floats], np.float32)
    w = np.array([v for _, _, v in floats], np.float32)
    np.testing.assert_array_max_ulp(g, w, maxulp=TABLE_MAX_ULP)


def test_fit_matches_rust(campaign_dir: Path) -> None:
    segments = [s for r in gyrodrift.load_campaign(campaign_dir) for s in r.segments]
    (want,) = gyrodrift.fit(segments)
    (got,) = peer.fit(peer.Activation.of(s) for s in segments)
    assert got.unit_id == want.unit_id
    assert got.curve_names == want.curve_names
    # The peer implements the paper's model and the absolute baselines; the relative baseline's
    # note (its orders) is ours alone.
    assert got.notes == [n for n in want.notes if not n.startswith("relative baseline")]
    assert_tables_match(got.modified, json.loads(want.modified.to_json()))
    assert_tables_match(got.standard, json.loads(want.standard.to_json()))
    assert_tables_match(got.third_order, json.loads(want.third_order.to_json()))
    # The peer's tables correct like Rust's (same model, so the same corrector output).
    reference = json.loads(want.modified.to_json())["axes"][0]["reference_ms"]
    assert len(reference) == 8 and reference[0] == 2000
