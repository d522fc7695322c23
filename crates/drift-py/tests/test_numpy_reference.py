"""The polynomial baselines restated in numpy float32 (method.md, "Baselines") agree with the binding
bit for bit: an independent check that the binding passes values through unaltered."""

from __future__ import annotations

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import gyrodrift
from conftest import Model
from gyrodrift import Flags

f32 = np.float32


def evaluate(axis: dict, celsius: np.ndarray, margin: np.float32) -> tuple[np.ndarray, np.ndarray]:
    """`PolynomialAxis::evaluate`: clamp to the range, normalise to [-1, 1], Horner in f32."""
    low, high = (f32(v) for v in axis["range_celsius"])
    clamped = np.minimum(np.maximum(celsius, low), high)
    outside = (celsius < low - margin) | (celsius > high + margin)
    half = f32(0.5) * (high - low)
    x = (clamped - (low + half)) / half
    value = np.zeros_like(celsius)
    for c in reversed(axis["coefficients"]):
        value = value * x + f32(c)
    return value, outside


def restated(tables: dict, switch_on_raw: np.ndarray, rate: np.ndarray, temperature: np.ndarray):
    s = tables["settings"]
    rpc, raw0, margin = (
        f32(s["raw_per_celsius"]),
        f32(s["raw_at_zero_celsius"]),
        f32(s["ambient_margin_celsius"]),
    )
    corrected, bias, flags = np.empty_like(rate), np.empty_like(rate), np.zeros(rate.shape, np.uint16)
    for a, axis in enumerate(tables["axes"]):
        # drift-core converts with the f32 reciprocal of the scale (one division per sample).
        per = f32(1.0) / rpc
        on, on_outside = evaluate(axis, (switch_on_raw[a : a + 1] - raw0) * per, margin)
        value, outside = evaluate(axis, (temperature[:, a] - raw0) * per, margin)
        bias[:, a] = on[0] + (value - on[0])
        corrected[:, a] = rate[:, a] - bias[:, a]
        flags[:, a] = np.where(outside, Flags.TEMPERATURE_OUT_OF_RANGE.value, 0)
        if on_outside[0]:
            flags[:, a] |= Flags.TEMPERATURE_OUT_OF_RANGE.value
    return corrected, bias, flags


@settings(max_examples=60, deadline=None)
@given(
    name=st.sampled_from(["standard", "third_order"]),
    switch_on=hnp.arrays(np.float32, 3, elements=st.floats(2000, 11000, width=32)),
    temperature=hnp.arrays(
        np.float32, st.tuples(st.integers(1, 300), st.just(3)), elements=st.floats(2000, 11000, width=32)
    ),
)
def test_polynomial_baselines_match_numpy(
    models: dict[str, Model], name: str, switch_on: np.ndarray, temperature: np.ndarray
) -> None:
    model = models[name]
    s = model.settings
    # No stuck-sensor detection: the restatement does not keep the repeat counter.
    model = model.with_settings(
        gyrodrift.Settings(
            raw_per_celsius=s.raw_per_celsius,
            raw_at_zero_celsius=s.raw_at_zero_celsius,
            ambient_margin_celsius=s.ambient_margin_celsius,
            rise_margin_celsius=s.rise_margin_celsius,
            stuck_after_samples=0,
        )
    )
    n = len(temperature)
    rate = np.linspace(-0.5, 0.5, n * 3, dtype=np.float32).reshape(n, 3)
    corrector = gyrodrift.Corrector(model)
    corrector.power_on(switch_on)
    got = corrector.correct_batch(np.arange(n, dtype=np.uint32), rate, temperature)
    want = restated(json.loads(model.to_json()), switch_on, rate, temperature)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(
            g.view(np.uint32) if g.dtype == np.float32 else g,
            w.view(np.uint32) if w.dtype == np.float32 else w,
        )
