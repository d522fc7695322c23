"""`gyrodrift.excess_cut`: the excess cut over the noise floor and its bootstrap interval."""

from __future__ import annotations

import numpy as np
import pytest

import gyrodrift


def test_the_ratio_is_that_of_the_means_and_the_interval_holds_it() -> None:
    rng = np.random.default_rng(7)
    before = 0.004 + 0.0005 * rng.standard_normal(48)
    after = 0.0025 + 0.0003 * rng.standard_normal(48)
    floor = 0.0015 + 0.0001 * rng.standard_normal(40)
    ratio, low, high = gyrodrift.excess_cut(before, after, floor)
    expected = (before.mean() - floor.mean()) / (after.mean() - floor.mean())
    assert ratio == pytest.approx(expected, rel=1e-12)
    assert low < ratio < high
    # Seeded: the same data, the same interval; float32 input gives the same figures to f32.
    assert gyrodrift.excess_cut(before, after, floor) == (ratio, low, high)
    ratio32, _, _ = gyrodrift.excess_cut(
        before.astype(np.float32), after.astype(np.float32), floor.astype(np.float32)
    )
    assert ratio32 == pytest.approx(ratio, rel=1e-4)


def test_a_larger_sample_narrows_the_interval() -> None:
    rng = np.random.default_rng(3)

    def width(n: int) -> float:
        before = 0.004 + 0.001 * rng.standard_normal(n)
        after = 0.0025 + 0.001 * rng.standard_normal(n)
        floor = 0.0015 + 0.0002 * rng.standard_normal(n)
        _, low, high = gyrodrift.excess_cut(before, after, floor)
        return high - low

    assert width(640) < 0.4 * width(40)


@pytest.mark.parametrize(
    ("before", "after", "floor", "message"),
    [
        (
            np.ones(3),
            np.ones(2),
            np.ones(3),
            "`after` must have one value per activation of `before` (3), got 2",
        ),
        (np.array([1.0, np.nan]), np.ones(2), np.ones(3), "`before` must be finite, got NaN at index 1"),
        (np.ones(2), np.ones(2), np.array([], dtype=np.float64), "`floor` has no values"),
        (np.ones(2), [1.0, 1.0], np.ones(3), "`after` must be a float32 or float64 array of shape (n,)"),
    ],
)
def test_bad_input_names_the_argument(before: object, after: object, floor: object, message: str) -> None:
    with pytest.raises(gyrodrift.InputError) as error:
        gyrodrift.excess_cut(before, after, floor)  # type: ignore[arg-type]
    assert message in str(error.value)
