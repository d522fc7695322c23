"""A plain numpy peer of gyrodrift's Rust code, written for the performance comparison.

The way a good numpy programmer would write it — whole-array operations, no Python loop per sample —
and doing the SAME work as the Rust code, so timing both compares equal work (tests/test_peer.py
checks that the outputs agree):

- `PeerCorrector`: drift-core's corrector (crates/drift-core/src/corrector.rs, table.rs, stage/*.rs,
  polynomial.rs) for the paper's ("modified") model and the polynomial baselines, on batches of
  samples, in float32 like the firmware: fault checks (non-finite rate or temperature, stuck sensor
  with its repeat counter), hold of the last good drift, the three stages and every flag. The tables
  are read through the Python API (`to_json`). Tables keyed by heating history and tables with warm
  starts are corrected as after `power_on` (nothing kept of the previous activation: a cold start,
  flagged `HISTORY_UNKNOWN`); there is no `power_on_after`. Tables with an extension's extra terms
  (which read auxiliary inputs) are not implemented: `PeerCorrector` rejects them (ValueError).
- `fit`: drift-fit's fit from segments (analyse.rs, lowpass.rs, curves.rs, knots.rs, fit.rs,
  baselines.rs): low-pass, switch-on temperature, initial bias, rise; curves averaged per
  (interval, activation); greedy reference times; tables; both polynomial baselines. In float64,
  quantised to float32 like the Rust code.

Where the peer differs from the Rust code (results agree within the tolerances of test_peer.py):

- Sums of many values use numpy's pairwise summation where Rust adds in order (f64: relative
  differences ~1e-16 before the float32 tables), and the baselines' 4×4 normal equations are solved
  by LAPACK (`numpy.linalg.solve`) instead of nalgebra's LU: both partial-pivoting LU, last-bit
  differences.
- The corrector's stage-3 search (which curves bracket the current rise) compares the rise with
  every curve at once (O(curves) per sample) instead of walking from the previous sample's bracket
  (O(1) per sample in Rust): the vectorised form of the same answer.
- The low-pass is evaluated only where it is used (the analysis grid and the initial-bias window),
  from the same running sum; Rust evaluates it at every sample. Same numbers, less work.
- No `power_off`/not-powered-on state and no error types: inputs are assumed valid (the benchmark's
  and the test's are); a failure raises `ValueError`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

import gyrodrift

F32 = np.float32
F64Array = NDArray[np.float64]
F32Array = NDArray[np.float32]
Model = Union[gyrodrift.ModifiedTables, gyrodrift.PolynomialTables]

RAW_PER_CELSIUS = 200.0  # drift_recording::RAW_PER_CELSIUS (the analysis' sensor scale)
MIN_RISE_CELSIUS = 0.05  # drift_fit::fit::MIN_RISE_CELSIUS
BLOCK = 1 << 15  # samples per block of the (samples × curves) arrays of stage 3

_AMBIENT_OUT_OF_RANGE = int(gyrodrift.Flags.AMBIENT_OUT_OF_RANGE)
_RISE_OUT_OF_SPAN = int(gyrodrift.Flags.RISE_OUT_OF_SPAN)
_PAST_LAST_REFERENCE = int(gyrodrift.Flags.PAST_LAST_REFERENCE)
_TEMPERATURE_OUT_OF_RANGE = int(gyrodrift.Flags.TEMPERATURE_OUT_OF_RANGE)
_TEMPERATURE_INVALID = int(gyrodrift.Flags.TEMPERATURE_INVALID)
_TEMPERATURE_STUCK = int(gyrodrift.Flags.TEMPERATURE_STUCK)
_RATE_INVALID = int(gyrodrift.Flags.RATE_INVALID)
_MODEL_INVALID = int(gyrodrift.Flags.MODEL_INVALID)
_HISTORY_UNKNOWN = int(gyrodrift.Flags.HISTORY_UNKNOWN)
_HISTORY_OUT_OF_SPAN = int(gyrodrift.Flags.HISTORY_OUT_OF_SPAN)


def _round(x: float) -> int:
    """Rust's `f64::round` (half away from zero), not Python's half-to-even."""
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


# --- correction -----------------------------------------------------------------------------------


def _lerp(lo: Any, hi: Any, fraction: Any) -> Any:
    """drift-core's `lerp` (float32 in, float32 out: no fused multiply-add, like Rust)."""
    return lo + (hi - lo) * fraction


@dataclass
class _ModifiedAxis:
    """One axis of the paper's tables, blended at the switch-on ambient (stage 2 is fixed for an
    activation): knots (curves × reference times) and the reference times."""

    reference_ms: NDArray[np.uint32]
    rise: F32Array  # (C, R) blended knots
    k: F32Array  # (C, R)
    initial_bias: np.float32
    flags: int
    # A table keyed by history: the curve below the activation's residual heat and the weight of
    # the next one (fixed for the activation; stage 3 then reads no rise). None: the paper's search.
    history: tuple[int, np.float32] | None = None


@dataclass
class _PolynomialAxis:
    low: np.float32
    high: np.float32
    coefficients: list[np.float32]
    at_switch_on: np.float32
    flags: int


def _polynomial(axis: _PolynomialAxis, celsius: F32Array, margin: np.float32) -> tuple[F32Array, Any]:
    """`PolynomialAxis::evaluate`: clamp to the range, normalise to [-1, 1], Horner in float32."""
    clamped = np.minimum(np.maximum(celsius, axis.low), axis.high)
    outside = np.isnan(celsius) | (celsius < axis.low - margin) | (celsius > axis.high + margin)
    half = F32(0.5) * (axis.high - axis.low)
    x = (clamped - (axis.low + half)) / half
    value = np.zeros_like(celsius)
    for c in reversed(axis.coefficients):
        value = value * x + c
    return value, outside


def _locate(at: F32Array, x: np.float32, margin: np.float32) -> tuple[int, int, np.float32, bool]:
    """`AmbientPosition::locate`: (lo, hi, weight, out of range) of `x` among increasing `at`."""
    above = int(np.searchsorted(at, x, side="right"))  # partition_point(a <= x)
    last = len(at) - 1
    if above == 0:
        return 0, 0, F32(0.0), bool(np.isnan(x) or x < at[0] - margin)
    if above <= last:
        lo = above - 1
        weight = F32((x - at[lo]) / (at[above] - at[lo]))
        return lo, (lo + 1 if weight > 0 else lo), weight, False
    return last, last, F32(0.0), bool(x > at[last] + margin)


def implements(model: Model) -> bool:
    """Whether `PeerCorrector` corrects `model`: everything but an extension's extra terms."""
    if isinstance(model, gyrodrift.PolynomialTables):
        return True
    return not json.loads(model.to_json()).get("extension", {}).get("terms")


class PeerCorrector:
    """drift-core's `Corrector` for one unit, in numpy: `power_on`, then `correct_batch` on blocks
    of samples that continue the same activation. Outputs are float32/uint16 arrays (n, 3)."""

    def __init__(self, model: Model) -> None:
        if not implements(model):
            raise ValueError("the peer does not implement the extension's extra terms")
        self.tables: dict[str, Any] = json.loads(model.to_json())
        self.modified = isinstance(model, gyrodrift.ModifiedTables)
        s = self.tables["settings"]
        self.raw_per_celsius = F32(s["raw_per_celsius"])
        self.raw_at_zero = F32(s["raw_at_zero_celsius"])
        self.ambient_margin = F32(s["ambient_margin_celsius"])
        self.rise_margin = F32(s["rise_margin_celsius"])
        self.stuck_after = int(s["stuck_after_samples"])
        self.axes: list[_ModifiedAxis | _PolynomialAxis] = []

    def _celsius(self, raw: Any) -> Any:
        # drift-core multiplies by the f32 reciprocal (computed once per sample, not divided per axis).
        return (raw - self.raw_at_zero) * (F32(1.0) / self.raw_per_celsius)

    def power_on(self, switch_on_raw: Sequence[float] | F32Array) -> tuple[int, int, int]:
        raw = np.asarray(switch_on_raw, dtype=np.float32)
        if not np.all(np.isfinite(raw)):
            raise ValueError("switch_on_raw must be finite")
        self.switch_on_raw = raw
        self.last_raw_bits = raw.view(np.uint32).copy()
        self.repeats = np.zeros(3, np.int64)
        self.drift = np.zeros(3, np.float32)
        self.axes = []
        for a, table in enumerate(self.tables["axes"]):
            celsius = self._celsius(raw[a])
            axis = (
                self._power_on_modified(table, celsius)
                if self.modified
                else self._power_on_polynomial(table, celsius)
            )
            if isinstance(axis, _ModifiedAxis) and not np.isfinite(axis.initial_bias):
                axis.flags |= _MODEL_INVALID  # the corrector keeps an initial bias of 0 then
                axis.initial_bias = F32(0.0)
            self.axes.append(axis)
        return (self.axes[0].flags, self.axes[1].flags, self.axes[2].flags)

    def _power_on_modified(self, table: Mapping[str, Any], celsius: np.float32) -> _ModifiedAxis:
        """`AmbientPosition::locate` and the blend of the two bracketing ambients' knots (stage 2);
        for a table keyed by history, the curves bracketing the residual heat (0: nothing kept)."""
        ambients = table["ambients"]
        at = np.array([a["ambient_celsius"] for a in ambients], np.float32)
        lo, hi, weight, out_of_range = _locate(at, celsius, self.ambient_margin)

        def knots(i: int) -> tuple[F32Array, F32Array]:
            points = np.array(
                [
                    [(p["rise_celsius"], p["k_dps_per_celsius"]) for p in c["points"]]
                    for c in ambients[i]["curves"]
                ],
                np.float32,
            )
            return points[:, :, 0], points[:, :, 1]

        rise, k = knots(lo)
        if weight > 0:
            rise_hi, k_hi = knots(hi)
            rise, k = _lerp(rise, rise_hi, weight), _lerp(k, k_hi, weight)
        bias = _lerp(F32(ambients[lo]["initial_bias_dps"]), F32(ambients[hi]["initial_bias_dps"]), weight)
        flags = _AMBIENT_OUT_OF_RANGE if out_of_range else 0
        history = None
        by_history = bool(ambients[0].get("residual_heat_celsius"))
        if by_history or any(a.get("warm_starts") for a in ambients):
            # Nothing kept of the previous activation: a cold start (no residual heat, so no
            # warm-start offset of the initial bias and the ambient at the switch-on temperature).
            flags |= _HISTORY_UNKNOWN
        if by_history:
            labels = np.array(ambients[lo]["residual_heat_celsius"], np.float32)
            upper = np.array(ambients[hi]["residual_heat_celsius"], np.float32)
            blended = _lerp(labels, upper, weight)
            h_lo, _h_hi, h_weight, h_out = _locate(blended, F32(0.0), self.rise_margin)
            history = (h_lo, h_weight)
            flags |= _HISTORY_OUT_OF_SPAN if h_out else 0
        return _ModifiedAxis(
            reference_ms=np.array(table["reference_ms"], np.uint32),
            rise=np.ascontiguousarray(rise),
            k=np.ascontiguousarray(k),
            initial_bias=F32(bias),
            flags=flags,
            history=history,
        )

    def _power_on_polynomial(self, table: Mapping[str, Any], celsius: np.float32) -> _PolynomialAxis:
        low, high = (F32(v) for v in table["range_celsius"])
        axis = _PolynomialAxis(low, high, [F32(c) for c in table["coefficients"]], F32(0.0), 0)
        value, outside = _polynomial(axis, np.array([celsius], np.float32), self.ambient_margin)
        axis.at_switch_on = F32(value[0])
        axis.flags = _TEMPERATURE_OUT_OF_RANGE if outside[0] else 0
        return axis

    def _drift_modified(
        self, axis: _ModifiedAxis, times: NDArray[np.uint32], rise: F32Array
    ) -> tuple[F32Array, NDArray[np.uint16]]:
        """Stages 1 and 3 (`Segment::locate`, `heating::cached_k` and `search`), block by block."""
        refs = axis.reference_ms
        last_ref = len(refs) - 1
        first = refs[0]
        drift = np.empty(len(times), np.float32)
        flags = np.zeros(len(times), np.uint16)
        count = axis.rise.shape[0]
        last_curve = count - 1
        history_k = None
        if axis.history is not None:
            # `heating::by_history`: one curve per activation, blended between the two histories.
            h, weight = axis.history
            history_k = axis.k[h] if not weight > 0 else _lerp(axis.k[h], axis.k[h + 1], weight)
        for start in range(0, len(times), BLOCK):
            t = times[start : start + BLOCK]
            r = rise[start : start + BLOCK]
            n = len(t)
            # Stage 1: reference-time segment, fraction of the way, rise scale before the first.
            lo = np.searchsorted(refs, t, side="right").astype(np.intp) - 1
            before = lo < 0
            lo = np.maximum(lo, 0)
            at_last = lo == last_ref
            hi = np.where(at_last, lo, lo + 1)
            offset = t - refs[lo]
            span = refs[hi] - refs[lo]
            fraction = np.where(
                at_last | before, F32(0.0), offset.astype(np.float32) / np.maximum(span, 1).astype(np.float32)
            )
            hi = np.where(before | (offset == 0), lo, hi)
            rise_scale = np.where(before, t.astype(np.float32) / F32(first), F32(1.0))
            past_last = at_last & (offset > 0) & ~before
            if history_k is not None:
                # No rise search: never out of the curves' span.
                drift[start : start + n] = _lerp(history_k[lo], history_k[hi], fraction) * r
                flags[start : start + n] = np.where(past_last, _PAST_LAST_REFERENCE, 0)
                continue
            # Every curve's point at this time: (n, C).
            rise_lo, rise_hi = axis.rise[:, lo].T, axis.rise[:, hi].T
            k_lo, k_hi = axis.k[:, lo].T, axis.k[:, hi].T
            f = fraction[:, None]
            points_rise = rise_scale[:, None] * _lerp(rise_lo, rise_hi, f)
            points_k = _lerp(k_lo, k_hi, f)
            # Stage 3: the last curve whose rise does not exceed the current one (else the first).
            below = np.count_nonzero(points_rise <= r[:, None], axis=1)
            c = np.clip(below - 1, 0, last_curve)
            rows = np.arange(n)
            c_up = np.minimum(c + 1, last_curve)
            lower_rise, lower_k = points_rise[rows, c], points_k[rows, c]
            upper_rise, upper_k = points_rise[rows, c_up], points_k[rows, c_up]
            under = r < lower_rise
            inside = ~under & (c < last_curve)
            with np.errstate(divide="ignore", invalid="ignore"):  # only where not `inside`
                frac = (r - lower_rise) / (upper_rise - lower_rise)
                k = np.where(inside, _lerp(lower_k, upper_k, frac), lower_k)
            beyond = np.where(
                under, r < lower_rise - self.rise_margin, ~inside & (r > lower_rise + self.rise_margin)
            )
            drift[start : start + n] = k * r
            flags[start : start + n] = np.where(beyond, _RISE_OUT_OF_SPAN, 0) | np.where(
                past_last, _PAST_LAST_REFERENCE, 0
            )
        return drift, flags

    def correct_batch(
        self, since_power_on_ms: NDArray[np.uint32], rate_dps: F32Array, temperature_raw: F32Array
    ) -> tuple[F32Array, F32Array, NDArray[np.uint16]]:
        """Corrects n samples in order, continuing the current activation (`Corrector::correct`
        per sample, `correct_axis` for the shared part)."""
        if not self.axes:
            raise ValueError("power_on first")
        n = len(since_power_on_ms)
        corrected = np.empty((n, 3), np.float32)
        bias = np.empty((n, 3), np.float32)
        flags = np.empty((n, 3), np.uint16)
        for a, axis in enumerate(self.axes):
            rate = np.ascontiguousarray(rate_dps[:, a], dtype=np.float32)
            raw = np.ascontiguousarray(temperature_raw[:, a], dtype=np.float32)
            f = np.full(n, axis.flags, np.uint16)
            f[~np.isfinite(rate)] |= _RATE_INVALID
            good = np.isfinite(raw)
            f[~good] |= _TEMPERATURE_INVALID
            # Stuck sensor: how many finite readings in a row repeated the previous one exactly
            # (the counter carries over from the previous block; a non-finite reading leaves it).
            where = np.flatnonzero(good)
            bits = raw[where].view(np.uint32)
            changed = bits != np.concatenate(([self.last_raw_bits[a]], bits[:-1]))
            steps = np.arange(1, len(bits) + 1)
            run_start = np.maximum.accumulate(np.where(changed, steps, 0))
            repeats = np.where(run_start == 0, self.repeats[a] + steps, steps - run_start)
            repeats = np.minimum(repeats, 65535)
            if len(bits):
                self.last_raw_bits[a] = bits[-1]
                self.repeats[a] = repeats[-1]
            stuck = np.zeros(n, bool)
            if self.stuck_after:
                stuck[where] = repeats >= self.stuck_after
            f[stuck] |= _TEMPERATURE_STUCK
            live = np.flatnonzero(good & ~stuck)
            live_raw = raw[live]
            if isinstance(axis, _ModifiedAxis):
                rise = (live_raw - self.switch_on_raw[a]) * (F32(1.0) / self.raw_per_celsius)
                drift, model_flags = self._drift_modified(axis, since_power_on_ms[live], rise)
                initial_bias = axis.initial_bias
            else:
                value, outside = _polynomial(axis, self._celsius(live_raw), self.ambient_margin)
                drift = value - axis.at_switch_on
                model_flags = np.where(outside, _TEMPERATURE_OUT_OF_RANGE, 0).astype(np.uint16)
                initial_bias = axis.at_switch_on
            finite = np.isfinite(drift)
            model_flags[~finite] |= _MODEL_INVALID
            f[live] |= model_flags
            # Hold the last good drift through faults: forward fill from the samples that set it.
            updates = live[finite]
            last_update = np.full(n, -1, np.intp)
            last_update[updates] = np.arange(len(updates))
            last_update = np.maximum.accumulate(last_update)
            held = np.concatenate((drift[finite], [self.drift[a]]))[last_update]
            if len(updates):
                self.drift[a] = held[-1]
            b = initial_bias + held
            bias[:, a] = b
            corrected[:, a] = rate - b
            flags[:, a] = f
        return corrected, bias, flags


# --- fitting --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FitSettings:
    """drift_fit::FitSettings with its defaults (the fields of `gyrodrift.FitSettings`)."""

    lowpass_window_s: float = 1.0
    grid_ms: int = 10
    initial_bias_window_s: float = 4.0
    switch_on_window_ms: int = 20
    first_reference_s: float = 2.0
    reference_count: int = 8
    reference_window_points: int = 10
    independent_after_min: float = 15.0
    polynomial_degree: int = 3


@dataclass
class Activation:
    """One segment's data as the fit needs it (from `gyrodrift.Segment`'s accessors)."""

    unit_id: str
    set_point_celsius: float
    series_kind: str
    interval_min: float | None
    activation: int
    repeat: int
    sample_rate_hz: int
    rate_dps: F32Array  # (n, 3)
    temperature_raw: NDArray[np.int16]  # (n, 3)

    @staticmethod
    def of(segment: gyrodrift.Segment) -> Activation:
        labels = segment.labels
        return Activation(
            unit_id=labels.unit_id,
            set_point_celsius=labels.set_point_celsius,
            series_kind=labels.series_kind,
            interval_min=labels.interval_min,
            activation=labels.activation,
            repeat=labels.repeat,
            sample_rate_hz=segment.sample_rate_hz,
            rate_dps=segment.rate_dps,
            temperature_raw=segment.temperature_raw,
        )


@dataclass
class Analysed:
    """`drift_fit::analyse::Analysed`: per axis, every `grid_ms` from switch-on."""

    source: Activation
    switch_on_raw: F32Array  # (3,)
    switch_on_celsius: F64Array  # (3,)
    initial_bias_dps: F64Array  # (3,)
    drift_dps: F32Array  # (3, m)
    rise_celsius: F32Array  # (3, m)


def _windowed_mean(prefix: F64Array, at: NDArray[np.intp], n: int, window: int) -> F64Array:
    """`centred_moving_average` (running sum in f64, window shrinking at both ends) at indices `at`."""
    half_before = window // 2
    half_after = (window - 1) - min(half_before, window - 1)
    lo = np.maximum(at - half_before, 0)
    hi = np.minimum(at + half_after + 1, n)
    result: F64Array = (prefix[hi] - prefix[lo]) / (hi - lo)
    return result


def _intercept(x: F64Array, y: F64Array) -> float:
    """Ordinary least-squares intercept of `y` against `x` (analyse.rs `intercept`)."""
    mx, my = x.mean(), y.mean()
    dx = x - mx
    sxx = float(dx @ dx)
    if sxx <= np.finfo(np.float64).eps:
        return float(my)
    return float(my - (dx @ (y - my)) / sxx * mx)


def analyse(activation: Activation, settings: FitSettings) -> Analysed:
    """`drift_fit::analyse::analyse`."""
    rate_hz = float(max(activation.sample_rate_hz, 1))
    per_ms = rate_hz / 1000.0
    n = len(activation.rate_dps)
    initial = _round(settings.initial_bias_window_s * rate_hz)
    switch_on = max(_round(settings.switch_on_window_ms * per_ms), 1)
    needed = max(initial, switch_on, math.ceil(settings.first_reference_s * rate_hz) + 1)
    if n < needed:
        raise ValueError(f"activation too short: {n} samples, {needed} needed")
    if np.any(activation.temperature_raw == np.iinfo(np.int16).min):
        raise ValueError("temperature reading missing (sensor dropout)")
    step = max(_round(settings.grid_ms * per_ms), 1)
    grid = np.arange(0, n, step)
    head = np.arange(initial)
    window = max(_round(settings.lowpass_window_s * rate_hz), 1)
    zero = np.zeros((1, 3))
    # Running sums of every channel at once (in order, f64, as the Rust running sum).
    temperature_sum = np.concatenate((zero, np.cumsum(activation.temperature_raw, axis=0, dtype=np.float64)))
    rate_sum = np.concatenate((zero, np.cumsum(activation.rate_dps, axis=0, dtype=np.float64)))
    on_raw = temperature_sum[switch_on] / switch_on
    drift = np.empty((3, len(grid)), np.float32)
    rise_grid = np.empty((3, len(grid)), np.float32)
    bias = np.empty(3)
    for axis in range(3):
        t_sum, r_sum = temperature_sum[:, axis], rate_sum[:, axis]
        rise_head = (_windowed_mean(t_sum, head, n, window) - on_raw[axis]) / RAW_PER_CELSIUS
        bias[axis] = _intercept(rise_head, activation.rate_dps[:initial, axis].astype(np.float64))
        drift[axis] = _windowed_mean(r_sum, grid, n, window) - bias[axis]
        rise_grid[axis] = (_windowed_mean(t_sum, grid, n, window) - on_raw[axis]) / RAW_PER_CELSIUS
    return Analysed(
        source=activation,
        switch_on_raw=on_raw.astype(np.float32),
        switch_on_celsius=on_raw / RAW_PER_CELSIUS,
        initial_bias_dps=bias,
        drift_dps=drift,
        rise_celsius=rise_grid,
    )


def _curve_key(a: Analysed, settings: FitSettings) -> tuple[int, int, int] | None:
    """`CurveKey::of`, as a sortable tuple: (0, 0, 0) is Independent, (1, interval_s, n) After."""
    s = a.source
    if s.series_kind != "protocol" or s.interval_min is None:
        return None
    if s.activation <= 1 or s.interval_min >= settings.independent_after_min:
        return (0, 0, 0)
    return (1, _round(s.interval_min * 60.0), s.activation)


@dataclass
class _SetPoint:
    set_point_celsius: float
    ambient_celsius: F64Array  # (3,)
    initial_bias_dps: F64Array  # (3,)
    keys: list[tuple[int, int, int]]
    drift: list[F64Array]  # per curve (3, m)
    rise: list[F64Array]


def _group(analysed: Sequence[Analysed], settings: FitSettings) -> list[_SetPoint]:
    """`curves::group`: per set point, per curve key, the mean of the member activations."""
    by_set_point: dict[int, dict[tuple[int, int, int], list[Analysed]]] = {}
    for a in analysed:
        key = _curve_key(a, settings)
        if key is not None:
            sp = _round(a.source.set_point_celsius * 1000.0)
            by_set_point.setdefault(sp, {}).setdefault(key, []).append(a)
    out = []
    for sp in sorted(by_set_point):
        curves = by_set_point[sp]
        independent = curves.get((0, 0, 0), [])
        count = max(len(independent), 1)
        ambient = (
            np.sum([m.switch_on_celsius for m in independent], axis=0) / count if independent else np.zeros(3)
        )
        bias = (
            np.sum([m.initial_bias_dps for m in independent], axis=0) / count if independent else np.zeros(3)
        )
        keys = sorted(curves)
        drift: list[F64Array] = []
        rise: list[F64Array] = []
        for key in keys:
            members = curves[key]
            m = min(len(a.drift_dps[0]) for a in members)
            for out_list, pick in ((drift, "drift_dps"), (rise, "rise_celsius")):
                stacked = [getattr(a, pick)[:, :m] for a in members]
                out_list.append(np.asarray(np.mean(stacked, axis=0, dtype=np.float64)))
        out.append(_SetPoint(sp / 1000.0, ambient, bias, keys, drift, rise))
    return out


def _padded(rows: Sequence[F64Array]) -> tuple[F64Array, NDArray[np.intp]]:
    """Rows of different lengths as one (rows, longest) array padded with NaN, and the lengths."""
    lengths = np.array([len(r) for r in rows], np.intp)
    out = np.full((len(rows), int(lengths.max())), np.nan)
    for i, r in enumerate(rows):
        out[i, : len(r)] = r
    return out, lengths


def _window_bounds(
    at: NDArray[np.intp], lengths: NDArray[np.intp], window: int
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """knots.rs windows: `lo = i − window/2`, `hi = min(lo + window, len)`; (K,) and (rows, K)."""
    lo = np.maximum(at - window // 2, 0)
    return lo, np.minimum(lo + max(window, 1), lengths[:, None])


def _k_window(
    drift: F64Array, rise: F64Array, lengths: NDArray[np.intp], at: NDArray[np.intp], window: int
) -> F64Array:
    """`knots::k_window` of every row (curve) at every index of `at`: the mean of drift / rise over
    the window, skipping rises within 1e-9 of zero (0 if none). Added in order, as Rust does: a loop
    over the window's offsets, vectorised over curves and indices."""
    lo, hi = _window_bounds(at, lengths, window)
    total = np.zeros((drift.shape[0], len(at)))
    count = np.zeros((drift.shape[0], len(at)), np.int64)
    for offset in range(max(window, 1)):
        j = np.minimum(lo + offset, drift.shape[1] - 1)
        r = rise[:, j]
        use = (lo + offset < hi) & (np.abs(r) > 1e-9)
        with np.errstate(divide="ignore", invalid="ignore"):
            total = np.where(use, total + drift[:, j] / r, total)
        count += use
    result: F64Array = np.where(count > 0, total / np.maximum(count, 1), 0.0)
    return result


def _mean_window(values: F64Array, lengths: NDArray[np.intp], at: NDArray[np.intp], window: int) -> F64Array:
    """`knots::mean_window` of every row at every index of `at` (added in order)."""
    lo, hi = _window_bounds(at, lengths, window)
    total = np.zeros((values.shape[0], len(at)))
    for offset in range(max(window, 1)):
        j = np.minimum(lo + offset, values.shape[1] - 1)
        total = np.where(lo + offset < hi, total + values[:, j], total)
    result: F64Array = total / np.maximum(hi - lo, 1)
    return result


def _choose(
    drift: F64Array, rise: F64Array, lengths: NDArray[np.intp], first: int, count: int, window: int
) -> list[int]:
    """`knots::choose` for one axis; `drift`, `rise` are the curves of every set point, padded."""
    length = int(lengths.min())
    if length <= first + 1 or count < 2:
        return [min(first, max(length - 1, 0))]
    knots = [first, length - 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        pointwise = np.where(np.abs(rise[:, :length]) > 1e-9, drift[:, :length] / rise[:, :length], 0.0)
    candidates = np.arange(first, length)
    while len(knots) < count:
        at = np.array(knots)
        at_knots = _k_window(drift, rise, lengths, at, window)  # (curves, knots)
        segment = np.searchsorted(at, candidates, side="right") - 1
        segment = np.minimum(segment, len(knots) - 2)
        a, b = at[segment], at[segment + 1]
        w = (candidates - a) / (b - a)
        k_lo, k_hi = at_knots[:, segment], at_knots[:, segment + 1]
        k_table = k_lo + (k_hi - k_lo) * w
        error = np.abs((k_table - pointwise[:, first:]) * rise[:, first:length])
        error[:, np.isin(candidates, at)] = 0.0
        error = np.nan_to_num(error, nan=0.0)
        flat = int(np.argmax(error.T))  # first maximum in (index, curve) order, like Rust's scan
        i, c = divmod(flat, error.shape[0])
        if not error[c, i] > 0.0:
            break
        knots = sorted([*knots, int(candidates[i])])
    return knots


def _strictly_increasing(values: F32Array) -> int:
    """fit.rs `strictly_increasing` (nudges ties upwards by a relative 1e-6)."""
    nudged = 0
    for i in range(1, len(values)):
        if values[i] <= values[i - 1]:
            values[i] = values[i - 1] + max(abs(values[i - 1]) * F32(1e-6), F32(1e-6))
            nudged += 1
    return nudged


def _solve(xs: F64Array, ys: F64Array, degree: int) -> list[float]:
    """baselines.rs `solve`: normal equations of the polynomial fit, solved by LU."""
    columns = degree + 1
    powers = np.empty((len(xs), 2 * columns))
    powers[:, 0] = 1.0
    for p in range(1, 2 * columns):
        powers[:, p] = powers[:, p - 1] * xs
    sums = powers.sum(axis=0)
    normal = sums[np.add.outer(np.arange(columns), np.arange(columns))]
    rhs = powers[:, :columns].T @ ys
    try:
        return [float(v) for v in np.linalg.solve(normal, rhs)]
    except np.linalg.LinAlgError:
        return [float(ys.mean()) if len(ys) else 0.0]


def _pairs(activations: Sequence[Analysed], axis: int) -> tuple[F64Array, F64Array]:
    """(temperature °C, low-frequency rate °/s) of every grid point of `activations`."""
    if not activations:
        return np.zeros(0), np.zeros(0)
    t = np.concatenate(
        [a.switch_on_celsius[axis] + a.rise_celsius[axis].astype(np.float64) for a in activations]
    )
    b = np.concatenate([a.initial_bias_dps[axis] + a.drift_dps[axis].astype(np.float64) for a in activations])
    return t, b


def _range(t: F64Array) -> tuple[float, float]:
    lo, hi = (float(t.min()), float(t.max())) if len(t) else (math.inf, -math.inf)
    return (lo, hi) if hi > lo else (lo - 0.5, lo + 0.5)


def _normalise(r: tuple[float, float], t: Any) -> Any:
    half = 0.5 * (r[1] - r[0])
    return (t - (r[0] + half)) / half


def _polynomial_axis(r: tuple[float, float], coefficients: Iterable[float]) -> dict[str, Any]:
    return {
        "range_celsius": [float(F32(r[0])), float(F32(r[1]))],
        "coefficients": [float(F32(c)) for c in list(coefficients)[:8]],
    }


@dataclass
class FittedUnit:
    """What `fit` returns per unit: the tables in drift-core's JSON structure (`to_json`)."""

    unit_id: str
    modified: dict[str, Any]
    standard: dict[str, Any]
    third_order: dict[str, Any]
    curve_names: list[str]
    notes: list[str]


def _default_settings(sample_rate_hz: float) -> dict[str, Any]:
    """drift-core's default `Settings` (what the fit stores with every table), from the Python API,
    stating the recordings' sample rate."""
    s = gyrodrift.Settings()
    return {
        "raw_per_celsius": s.raw_per_celsius,
        "raw_at_zero_celsius": s.raw_at_zero_celsius,
        "ambient_margin_celsius": s.ambient_margin_celsius,
        "rise_margin_celsius": s.rise_margin_celsius,
        "stuck_after_samples": s.stuck_after_samples,
        "sample_rate_hz": sample_rate_hz,
    }


def _key_name(key: tuple[int, int, int]) -> str:
    if key[0] == 0:
        return "independent"
    interval_s, activation = key[1], key[2]
    return f"{interval_s // 60}min#{activation}" if interval_s % 60 == 0 else f"{interval_s}s#{activation}"


def fit_unit(activations: Sequence[Analysed], settings: FitSettings) -> FittedUnit:
    """`drift_fit::fit::fit_unit` (settings assumed valid)."""
    unit_id = activations[0].source.unit_id if activations else ""
    set_points = _group(activations, settings)
    if not set_points:
        raise ValueError("no protocol activations to fit")
    common = set(set_points[0].keys)
    for sp in set_points[1:]:
        common &= set(sp.keys)
    if (0, 0, 0) not in common:
        raise ValueError("a set point has no independent activation")
    notes: list[str] = []
    for sp in set_points:
        keep = [i for i, k in enumerate(sp.keys) if k in common]
        if len(keep) < len(sp.keys):
            notes.append(
                f"{sp.set_point_celsius} °C: {len(sp.keys) - len(keep)} curves dropped"
                " (not present at every set point)"
            )
        sp.keys = [sp.keys[i] for i in keep]
        sp.drift = [sp.drift[i] for i in keep]
        sp.rise = [sp.rise[i] for i in keep]
    grid_ms = settings.grid_ms
    first = _round(settings.first_reference_s * 1000.0 / grid_ms)
    shortest = min(d.shape[1] for sp in set_points for d in sp.drift)
    if shortest <= first + 1:
        raise ValueError("activations end before the first reference time")
    window = settings.reference_window_points
    axes = []
    for axis in range(3):
        drift_all, lengths = _padded([d[axis] for sp in set_points for d in sp.drift])
        rise_all, _ = _padded([r[axis] for sp in set_points for r in sp.rise])
        if not np.any(np.abs(np.nan_to_num(rise_all)) >= MIN_RISE_CELSIUS):
            raise ValueError(f"axis {axis}: the temperature never rises")
        knots = _choose(drift_all, rise_all, lengths, first, settings.reference_count, window)
        at = np.array(knots)
        ambients = []
        last_ambient = -math.inf
        for sp in set_points:
            ambient = F32(sp.ambient_celsius[axis])
            if ambient <= last_ambient:
                raise ValueError(f"axis {axis}: switch-on temperature not above the previous set point's")
            last_ambient = float(ambient)
            # Every curve of this set point at every reference time: (curves, knots).
            drift_sp, lengths_sp = _padded([d[axis] for d in sp.drift])
            rise_sp, _ = _padded([r[axis] for r in sp.rise])
            rises = _mean_window(rise_sp, lengths_sp, at, window).astype(np.float32)
            ks = _k_window(drift_sp, rise_sp, lengths_sp, at, window).astype(np.float32)
            order = np.argsort(rises, axis=0, kind="stable")
            rises = np.take_along_axis(rises, order, axis=0)
            ks = np.take_along_axis(ks, order, axis=0)
            for j in range(len(knots)):
                column = rises[:, j].copy()
                nudged = _strictly_increasing(column)
                if nudged:
                    notes.append(
                        f"axis {axis}, {sp.set_point_celsius} °C, reference {j}: {nudged} tied rises nudged"
                    )
                rises[:, j] = column
            ambients.append(
                {
                    "ambient_celsius": float(ambient),
                    "initial_bias_dps": float(F32(sp.initial_bias_dps[axis])),
                    "curves": [
                        {
                            "points": [
                                {"rise_celsius": float(rises[c, j]), "k_dps_per_celsius": float(ks[c, j])}
                                for j in range(len(knots))
                            ]
                        }
                        for c in range(rises.shape[0])
                    ],
                }
            )
        axes.append({"reference_ms": [k * grid_ms for k in knots], "ambients": ambients})
    # The activations' one sample rate (0, not stated, when they differ).
    rates = {a.source.sample_rate_hz for a in activations}
    settings_json = _default_settings(float(rates.pop()) if len(rates) == 1 else 0.0)
    protocol = [a for a in activations if _curve_key(a, settings) is not None]
    by_set_point = [
        [a for a in protocol if abs(a.source.set_point_celsius - sp.set_point_celsius) < 1e-6]
        for sp in set_points
    ]
    standard, third_order = [], []
    for axis in range(3):
        everything = [a for group in by_set_point for a in group]
        r = _range(_pairs(everything, axis)[0])
        points = [_pairs(group, axis) for group in by_set_point if group]
        xs = np.array([_normalise(r, t.mean()) for t, _ in points])
        ys = np.array([b.mean() for _, b in points])
        degree = min(max(len(points), 1), 8) - 1
        standard.append(_polynomial_axis(r, _solve(xs, ys, degree)))
        t, b = _pairs(protocol, axis)
        r = _range(t)
        third_order.append(
            _polynomial_axis(r, _solve(_normalise(r, t), b, min(settings.polynomial_degree, 7)))
        )
    return FittedUnit(
        unit_id=unit_id,
        # The paper's tables as drift-core writes them: no extra terms, the rate filter at rest.
        modified={"settings": settings_json, "axes": axes, "extension": _NO_EXTENSION},
        standard={"settings": settings_json, "axes": standard},
        third_order={"settings": settings_json, "axes": third_order},
        curve_names=[_key_name(k) for k in sorted(common)],
        notes=notes,
    )


def is_calibration(activation: Activation, set_points: Sequence[float] = (30.0, 40.0)) -> bool:
    """A protocol activation at a calibration set point (what the fit uses)."""
    return activation.series_kind == "protocol" and any(
        abs(s - activation.set_point_celsius) < 1e-6 for s in set_points
    )


_NO_EXTENSION: dict[str, Any] = {
    "terms": [],
    "switch_on_rate": [
        {"heating_celsius_per_s": 0.0, "cooling_per_second": 0.0, "cooling_per_second_per_remaining": 0.0}
    ]
    * 3,
}


def fit(
    activations: Iterable[Activation],
    *,
    calibration: Sequence[float] = (30.0, 40.0),
    settings: FitSettings | None = None,
) -> list[FittedUnit]:
    """`gyrodrift.fit` from segments: analyse every calibration activation, fit each unit (sorted by
    unit id)."""
    settings = settings or FitSettings()
    by_unit: dict[str, list[Analysed]] = {}
    for a in activations:
        if is_calibration(a, calibration):
            by_unit.setdefault(a.unit_id, []).append(analyse(a, settings))
    return [fit_unit(by_unit[unit], settings) for unit in sorted(by_unit)]
