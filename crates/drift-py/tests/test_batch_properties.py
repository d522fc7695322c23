"""Properties of the batch path on generated data: it is the per-sample corrector, sample by sample,
however the stream is split, from any thread."""

from __future__ import annotations

import threading

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import gyrodrift
from conftest import Model

finite_or_not = st.floats(width=32, allow_nan=True, allow_infinity=True)


@st.composite
def streams(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = draw(st.integers(1, 1500))
    steps = draw(hnp.arrays(np.uint32, n, elements=st.integers(0, 500)))
    times = np.cumsum(steps, dtype=np.uint64).clip(0, 2**32 - 1).astype(np.uint32)
    base = draw(st.floats(3000, 9000))  # 15..45 °C switch-on
    rise = np.cumsum(draw(hnp.arrays(np.float32, (n, 3), elements=st.floats(-2, 6, width=32))), axis=0)
    temperature = (base + rise).astype(np.float32)
    rate = draw(hnp.arrays(np.float32, (n, 3), elements=st.floats(-1, 1, width=32)))
    # A few special values anywhere (NaN, inf, huge).
    for _ in range(draw(st.integers(0, 4))):
        i, axis = draw(st.integers(0, n - 1)), draw(st.integers(0, 2))
        target = draw(st.sampled_from([rate, temperature]))
        target[i, axis] = draw(finite_or_not)
    return times, rate, temperature


def per_sample(corrector: gyrodrift.Corrector, times: np.ndarray, rate: np.ndarray, temperature: np.ndarray):
    outs = [corrector.correct(int(t), r, T) for t, r, T in zip(times, rate, temperature)]
    return (
        np.array([o.corrected_dps for o in outs], dtype=np.float32),
        np.array([o.bias_dps for o in outs], dtype=np.float32),
        np.array([o.flags for o in outs], dtype=np.uint16),
    )


def assert_same(a: tuple, b: tuple) -> None:
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)  # NaN == NaN here; bit-level checks are in test_vectors


@settings(max_examples=40, deadline=None)
@given(stream=streams(), model_name=st.sampled_from(["modified", "standard", "third_order"]))
def test_batch_equals_per_sample(models: dict[str, Model], stream: tuple, model_name: str) -> None:
    times, rate, temperature = stream
    switch_on = temperature[0].astype(np.float64)
    if not np.isfinite(switch_on).all():
        switch_on = np.array([6000.0, 6000.0, 6000.0])
    batch = gyrodrift.Corrector(models[model_name])
    single = gyrodrift.Corrector(models[model_name])
    batch.power_on(switch_on)
    single.power_on(switch_on)
    assert_same(batch.correct_batch(times, rate, temperature), per_sample(single, times, rate, temperature))


@settings(max_examples=40, deadline=None)
@given(stream=streams(), cuts=st.lists(st.integers(0, 1500), max_size=5))
def test_any_split_gives_the_same_result(
    modified: gyrodrift.ModifiedTables, stream: tuple, cuts: list[int]
) -> None:
    times, rate, temperature = stream
    n = len(times)
    bounds = sorted({0, n, *(c for c in cuts if c < n)})
    whole, parts = gyrodrift.Corrector(modified), gyrodrift.Corrector(modified)
    whole.power_on([6000.0] * 3)
    parts.power_on([6000.0] * 3)
    expected = whole.correct_batch(times, rate, temperature)
    pieces = [
        parts.correct_batch(times[a:b], rate[a:b], temperature[a:b]) for a, b in zip(bounds, bounds[1:])
    ]
    assert_same(expected, tuple(np.concatenate(p) for p in zip(*pieces)))


def test_threads_correct_independently(modified: gyrodrift.ModifiedTables) -> None:
    """The GIL is released during a batch: correctors in several threads give the serial results."""
    n = 200_000
    times = np.arange(n, dtype=np.uint32)
    rise = np.linspace(0.0, 800.0, n, dtype=np.float32)[:, None]
    temperature = (np.float32(6000.0) + rise * np.array([1.0, 0.9, 1.1], dtype=np.float32)).astype(np.float32)
    rate = np.full((n, 3), 0.05, dtype=np.float32)

    def run() -> tuple:
        corrector = gyrodrift.Corrector(modified)
        corrector.power_on(temperature[0])
        return corrector.correct_batch(times, rate, temperature)

    expected = run()
    results: list[tuple] = [()] * 4
    threads = [threading.Thread(target=lambda i=i: results.__setitem__(i, run())) for i in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for result in results:
        assert_same(expected, result)
