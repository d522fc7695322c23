"""The stillness learner restated in numpy float32 agrees with the binding bit for bit, learns a
constant offset while still, and learns nothing while the instrument turns."""

from __future__ import annotations

import numpy as np
import pytest

import gyrodrift

f32 = np.float32
FS = 100.0


def restated(rates: np.ndarray, accel: np.ndarray, every: int, s: dict, time_constant_s: float):
    """`StillnessLearner::update` and `accelerometer`, one sample at a time, in float32."""

    def step(time_constant, rate):
        return min(f32(1.0) / (f32(time_constant) * f32(rate)), f32(1.0))

    rate_alpha = step(s["variance_time_constant_s"], s["sample_rate_hz"])
    accel_alpha = step(s["variance_time_constant_s"], s["accel_rate_hz"])
    gain = step(time_constant_s, s["sample_rate_hz"])
    threshold = f32(s["rate_threshold_dps"])
    rate_var_max = f32(s["rate_sd_threshold_dps"]) * f32(s["rate_sd_threshold_dps"])
    accel_var_max = f32(s["accel_sd_threshold_g"]) * f32(s["accel_sd_threshold_g"])
    still_for = f32(s["still_for_s"]) * f32(s["sample_rate_hz"])

    def push(mean, var, value, alpha):
        deviation = f32(value - mean)
        step_ = f32(alpha * deviation)
        return f32(mean + step_), f32((f32(1.0) - alpha) * f32(var + f32(deviation * step_)))

    offset = [f32(0.0)] * 3
    rate_mean, rate_var = [f32(0.0)] * 3, [f32(0.0)] * 3
    acc_mean, acc_var = [f32(0.0)] * 3, [f32(0.0)] * 3
    accel_seen, timer = False, 0
    out = np.empty_like(rates)
    still_out = np.zeros(len(rates), bool)
    learning_out = np.zeros(len(rates), bool)
    for i, rate in enumerate(rates):
        if i % every == 0 and i // every < len(accel):
            a = accel[i // every]
            if np.all(np.isfinite(a)):
                if not accel_seen:
                    acc_mean, acc_var, accel_seen = [f32(v) for v in a], [f32(0.0)] * 3, True
                else:
                    for k in range(3):
                        acc_mean[k], acc_var[k] = push(acc_mean[k], acc_var[k], a[k], accel_alpha)
        corrected = [f32(rate[k] - offset[k]) for k in range(3)]
        out[i] = corrected
        if not all(np.isfinite(corrected)):
            timer = 0
            continue
        still = True
        for k in range(3):
            rate_mean[k], rate_var[k] = push(rate_mean[k], rate_var[k], rate[k], rate_alpha)
            still &= bool(abs(corrected[k]) <= threshold and rate_var[k] <= rate_var_max)
        if accel_seen:
            total = f32(f32(f32(f32(0.0) + acc_var[0]) + acc_var[1]) + acc_var[2])
            still &= bool(total <= accel_var_max)
        if not still:
            timer, learning = 0, False
        elif f32(timer) < still_for:
            timer, learning = timer + 1, False
        else:
            learning = True
        if learning:
            offset = [f32(offset[k] + f32(gain * corrected[k])) for k in range(3)]
        still_out[i], learning_out[i] = still, learning
    return out, still_out, learning_out, offset


def motion(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Still, a turn about X, still again: rates at 100 Hz with an offset, accelerometer at 50 Hz."""
    rng = np.random.default_rng(seed)
    n = int(60 * FS)
    offset = np.array([0.02, -0.015, 0.01])
    body = np.zeros((n, 3))
    body[int(20 * FS) : int(25 * FS), 0] = 30.0
    rates = (offset + body + 0.005 * rng.standard_normal((n, 3))).astype(np.float32)
    angle = np.cumsum(np.radians(body[::2, 0]) / (FS / 2))
    accel = np.stack([np.zeros_like(angle), np.sin(angle), np.cos(angle)], axis=1)
    accel = (accel + 0.001 * rng.standard_normal(accel.shape)).astype(np.float32)
    accel[100] = np.nan  # a dropout the learner skips
    return rates, accel, offset


SETTINGS = dict(
    sample_rate_hz=FS,
    accel_rate_hz=FS / 2,
    rate_threshold_dps=3.0,
    rate_sd_threshold_dps=0.1,
    accel_sd_threshold_g=0.01,
    variance_time_constant_s=0.5,
    still_for_s=5.0,
)


@pytest.mark.parametrize("seed", [1, 2])
def test_batch_matches_the_numpy_restatement_bit_for_bit(seed: int) -> None:
    rates, accel, offset = motion(seed)
    learner = gyrodrift.StillnessLearner(**SETTINGS)
    got, still, learning = learner.update_batch(rates, accel, accel_every=2)
    want, want_still, want_learning, want_offset = restated(
        rates, accel, 2, SETTINGS, learner.time_constant_s
    )
    assert got.dtype == np.float32 and got.shape == rates.shape
    np.testing.assert_array_equal(got.view(np.uint32), want.view(np.uint32))
    np.testing.assert_array_equal(still, want_still)
    np.testing.assert_array_equal(learning, want_learning)
    assert learner.offset_dps == tuple(float(v) for v in want_offset)
    # The turn (20–25 s) is never still, and the learned offset is the true one within the noise.
    assert not still[int(20 * FS) : int(25 * FS)].any()
    assert learning[int(10 * FS) : int(20 * FS)].all()
    np.testing.assert_allclose(learner.offset_dps, offset, atol=2e-3)


def test_one_sample_at_a_time_equals_the_batch() -> None:
    rates, accel, _ = motion(3)
    batch = gyrodrift.StillnessLearner(**SETTINGS)
    whole, _, _ = batch.update_batch(rates, accel, accel_every=2)
    single = gyrodrift.StillnessLearner(**SETTINGS)
    for i, rate in enumerate(rates):
        if i % 2 == 0:
            single.accelerometer(accel[i // 2])
        got, _, _ = single.update(rate)
        assert np.array_equal(np.array(got, np.float32), whole[i]), i
    assert single.offset_dps == batch.offset_dps


def test_a_kept_offset_is_removed_from_the_first_sample() -> None:
    learner = gyrodrift.StillnessLearner(**SETTINGS)
    learner.set_offset([0.5, -0.25, 0.0])
    (x, y, z), still, learning = learner.update([0.5, -0.25, 0.0])
    assert (x, y, z) == (0.0, 0.0, 0.0) and still and not learning


def test_bad_settings_and_inputs_are_named() -> None:
    with pytest.raises(gyrodrift.InputError, match="time_constant_s"):
        gyrodrift.StillnessLearner(time_constant_s=0.0)
    with pytest.raises(gyrodrift.InputError, match="still_for_s"):
        gyrodrift.StillnessLearner(still_for_s=float("nan"))
    learner = gyrodrift.StillnessLearner()
    with pytest.raises(gyrodrift.InputError, match="offset_dps"):
        learner.set_offset([0.0, float("inf"), 0.0])
    with pytest.raises(gyrodrift.InputError, match="rate_dps"):
        learner.update_batch(np.zeros((4, 2), np.float32))
    with pytest.raises(gyrodrift.InputError, match="accel_every"):
        learner.update_batch(np.zeros((4, 3), np.float32), accel_every=0)
