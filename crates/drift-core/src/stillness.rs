//! Run-time offset learning while the instrument stands still, after the tables.
//!
//! The tables remove the drift that follows switch-on; what they cannot know is the slow offset of
//! this unit on this day (ageing, a mounting stress, a warm restart outside the calibration). A
//! learner in the manner of x-io Fusion's gyroscope offset correction estimates that offset from
//! the rate while the instrument is still: a still detector (every axis within a rate threshold of
//! the learned offset, the rate's and, when an accelerometer is present, the acceleration's moving
//! standard deviation below a threshold) held for a while, then a first-order low-pass of the rate
//! towards the offset. Fed with the tables' corrected rate it learns only what the tables left;
//! fed with the raw rate it is the learner alone.
//!
//! It is a call of its own, not part of [`crate::Corrector::correct`]: firmware that has no still
//! periods leaves it out at no cost, and the corrector's per-sample work is unchanged.

use crate::error::{Error, Location, Problem};
use crate::AXES;

/// What the learner is told, in physical units. [`StillnessSettings::default`] is Fusion's
/// offset-correction constants (3 °/s threshold, 5 s timeout, 0.02 Hz cut-off, an 8 s time
/// constant) with the variance tests added.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct StillnessSettings {
    /// Rate of [`StillnessLearner::update`] calls, Hz.
    pub sample_rate_hz: f32,
    /// Rate of [`StillnessLearner::accelerometer`] calls, Hz.
    pub accel_rate_hz: f32,
    /// Still only while every axis's rate, less the learned offset, is within this, °/s.
    pub rate_threshold_dps: f32,
    /// Still only while every axis's moving standard deviation of the rate is below this, °/s.
    pub rate_sd_threshold_dps: f32,
    /// Still only while the acceleration's moving standard deviation (all axes together) is below
    /// this, g. Ignored until the first accelerometer reading.
    pub accel_sd_threshold_g: f32,
    /// Time constant of the moving mean and variance behind both standard deviations, s.
    pub variance_time_constant_s: f32,
    /// How long the instrument must have been still before the offset moves, s.
    pub still_for_s: f32,
    /// Time constant of the offset's low-pass while still, s.
    pub time_constant_s: f32,
}

impl Default for StillnessSettings {
    fn default() -> Self {
        Self {
            sample_rate_hz: 1000.0,
            accel_rate_hz: 100.0,
            rate_threshold_dps: 3.0,
            rate_sd_threshold_dps: 0.1,
            accel_sd_threshold_g: 0.01,
            variance_time_constant_s: 0.5,
            still_for_s: 5.0,
            time_constant_s: 1.0 / (2.0 * core::f32::consts::PI * 0.02),
        }
    }
}

impl StillnessSettings {
    /// The settings in field order, as the shared test vectors and firmware images keep them.
    pub const fn to_array(&self) -> [f32; 8] {
        [
            self.sample_rate_hz,
            self.accel_rate_hz,
            self.rate_threshold_dps,
            self.rate_sd_threshold_dps,
            self.accel_sd_threshold_g,
            self.variance_time_constant_s,
            self.still_for_s,
            self.time_constant_s,
        ]
    }

    /// The settings from [`Self::to_array`]'s order (not validated: [`StillnessLearner::new`]
    /// checks them).
    pub const fn from_array(values: [f32; 8]) -> Self {
        let [sample_rate_hz, accel_rate_hz, rate_threshold_dps, rate_sd_threshold_dps, accel_sd_threshold_g, variance_time_constant_s, still_for_s, time_constant_s] =
            values;
        Self {
            sample_rate_hz,
            accel_rate_hz,
            rate_threshold_dps,
            rate_sd_threshold_dps,
            accel_sd_threshold_g,
            variance_time_constant_s,
            still_for_s,
            time_constant_s,
        }
    }
}

/// A moving mean and variance of one signal (exponential weights): the mean moves by `alpha` of
/// each deviation, the variance by the West/Finch update, which stays non-negative.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Moving {
    mean: f32,
    variance: f32,
}

impl Moving {
    #[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
    fn push(&mut self, value: f32, alpha: f32) {
        let deviation = value - self.mean;
        let step = alpha * deviation;
        self.mean += step;
        self.variance = (1.0 - alpha) * (self.variance + deviation * step);
    }
}

/// The learner: validated coefficients (immutable) and its state (offset, still timer, moving
/// statistics). Plain data: copy it to persist the learned offset across power-off.
///
/// With the `serde` feature it serialises whole (coefficients and state), for a host to save and
/// restore a learner mid-run; firmware keeps only [`StillnessLearner::offset_dps`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StillnessLearner {
    rate_threshold_dps: f32,
    rate_variance_threshold: f32,
    accel_variance_threshold: f32,
    rate_alpha: f32,
    accel_alpha: f32,
    gain: f32,
    /// Kept in f32: the comparison with the timer is exact to 2^24 samples, hours at 1 kHz.
    still_for_samples: f32,
    offset_dps: [f32; AXES],
    rate: [Moving; AXES],
    accel: [Moving; AXES],
    accel_seen: bool,
    still_samples: u32,
}

/// The learner's answer for one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StillnessOutput {
    /// Rate less the offset learned before this sample, °/s.
    pub rate_dps: [f32; AXES],
    /// Whether the detector took this sample as still.
    pub still: bool,
    /// Whether this sample moved the offset (still for long enough).
    pub learning: bool,
}

impl StillnessLearner {
    /// A learner with no offset learned. Refuses a non-finite or non-positive setting, naming it.
    pub fn new(settings: &StillnessSettings) -> Result<Self, Error> {
        let StillnessSettings {
            sample_rate_hz,
            accel_rate_hz,
            rate_threshold_dps,
            rate_sd_threshold_dps,
            accel_sd_threshold_g,
            variance_time_constant_s,
            still_for_s,
            time_constant_s,
        } = *settings;
        let positive = [
            ("sample_rate_hz", sample_rate_hz),
            ("accel_rate_hz", accel_rate_hz),
            ("rate_threshold_dps", rate_threshold_dps),
            ("rate_sd_threshold_dps", rate_sd_threshold_dps),
            ("accel_sd_threshold_g", accel_sd_threshold_g),
            ("variance_time_constant_s", variance_time_constant_s),
            ("time_constant_s", time_constant_s),
        ];
        for (field, value) in positive {
            check(field, value, Problem::NotPositive, value > 0.0)?;
        }
        check(
            "still_for_s",
            still_for_s,
            Problem::Negative,
            still_for_s >= 0.0,
        )?;
        // A first-order step of 1/(τ·fs), capped at 1: a time constant shorter than the sample
        // period follows the input, it does not overshoot.
        let step = |time_constant: f32, rate: f32| (1.0 / (time_constant * rate)).min(1.0);
        Ok(Self {
            rate_threshold_dps,
            rate_variance_threshold: rate_sd_threshold_dps * rate_sd_threshold_dps,
            accel_variance_threshold: accel_sd_threshold_g * accel_sd_threshold_g,
            rate_alpha: step(variance_time_constant_s, sample_rate_hz),
            accel_alpha: step(variance_time_constant_s, accel_rate_hz),
            gain: step(time_constant_s, sample_rate_hz),
            still_for_samples: still_for_s * sample_rate_hz,
            offset_dps: [0.0; AXES],
            rate: [Moving::default(); AXES],
            accel: [Moving::default(); AXES],
            accel_seen: false,
            still_samples: 0,
        })
    }

    /// The offset learned so far, °/s.
    pub fn offset_dps(&self) -> [f32; AXES] {
        self.offset_dps
    }

    /// Starts from an offset kept from before (e.g. across power-off), with the detector cleared.
    /// A non-finite offset is refused, naming the axis, and the learner left unchanged.
    pub fn set_offset(&mut self, offset_dps: [f32; AXES]) -> Result<(), Error> {
        if let Some(axis) = offset_dps.iter().position(|v| !v.is_finite()) {
            return Err(Error::new(
                "offset_dps",
                Location::axis(axis),
                Problem::NonFinite,
            ));
        }
        self.offset_dps = offset_dps;
        self.reset_detector();
        Ok(())
    }

    /// Clears the detector (still timer, moving statistics) and keeps the offset: call it at
    /// switch-on, when the rate's statistics of the last activation no longer hold.
    pub fn reset_detector(&mut self) {
        self.rate = [Moving::default(); AXES];
        self.accel = [Moving::default(); AXES];
        self.accel_seen = false;
        self.still_samples = 0;
    }

    /// One accelerometer reading, g, at [`StillnessSettings::accel_rate_hz`]. A reading with a
    /// non-finite axis is skipped (a dropout), so it cannot poison the moving statistics.
    pub fn accelerometer(&mut self, accel_g: [f32; AXES]) {
        if accel_g.iter().any(|v| !v.is_finite()) {
            return;
        }
        if !self.accel_seen {
            // The first reading starts the mean where the signal is, not at zero g.
            for (moving, value) in self.accel.iter_mut().zip(accel_g) {
                *moving = Moving {
                    mean: value,
                    variance: 0.0,
                };
            }
            self.accel_seen = true;
            return;
        }
        for (moving, value) in self.accel.iter_mut().zip(accel_g) {
            moving.push(value, self.accel_alpha);
        }
    }

    /// One rate sample, °/s (the tables' corrected rate, or the raw rate for the learner alone),
    /// at [`StillnessSettings::sample_rate_hz`]. Returns it less the offset learned before it. A
    /// sample with a non-finite axis is passed through less the offset, taken as not still, and
    /// leaves the statistics as they were.
    #[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
    pub fn update(&mut self, rate_dps: [f32; AXES]) -> StillnessOutput {
        let mut rate = rate_dps;
        for (r, offset) in rate.iter_mut().zip(self.offset_dps) {
            *r -= offset;
        }
        if rate.iter().any(|v| !v.is_finite()) {
            self.still_samples = 0;
            return StillnessOutput {
                rate_dps: rate,
                still: false,
                learning: false,
            };
        }
        let mut still = true;
        for ((moving, value), corrected) in self.rate.iter_mut().zip(rate_dps).zip(rate) {
            moving.push(value, self.rate_alpha);
            still &= corrected.abs() <= self.rate_threshold_dps
                && moving.variance <= self.rate_variance_threshold;
        }
        if self.accel_seen {
            let variance: f32 = self.accel.iter().map(|m| m.variance).sum();
            still &= variance <= self.accel_variance_threshold;
        }
        // Fusion's order: the sample that completes the wait counts, the next one learns.
        let learning = if !still {
            self.still_samples = 0;
            false
        } else if (self.still_samples as f32) < self.still_for_samples {
            self.still_samples = self.still_samples.saturating_add(1);
            false
        } else {
            true
        };
        if learning {
            for (offset, r) in self.offset_dps.iter_mut().zip(rate) {
                *offset += self.gain * r;
            }
        }
        StillnessOutput {
            rate_dps: rate,
            still,
            learning,
        }
    }
}

fn check(field: &'static str, value: f32, problem: Problem, ok: bool) -> Result<(), Error> {
    if !value.is_finite() {
        return Err(Error::new(field, Location::default(), Problem::NonFinite));
    }
    if !ok {
        return Err(Error::new(field, Location::default(), problem));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> StillnessSettings {
        StillnessSettings {
            sample_rate_hz: 100.0,
            ..StillnessSettings::default()
        }
    }

    #[test]
    fn learns_a_constant_offset_while_still() {
        let mut learner = StillnessLearner::new(&settings()).unwrap();
        let offset = [0.02, -0.01, 0.005];
        // 5 s to qualify, then 10 time constants.
        for _ in 0..(100 * (5 + 80)) {
            learner.update(offset);
        }
        for (learned, truth) in learner.offset_dps().iter().zip(offset) {
            assert!((learned - truth).abs() < 1e-5, "{learned} vs {truth}");
        }
    }

    #[test]
    fn a_rotation_learns_nothing() {
        let mut learner = StillnessLearner::new(&settings()).unwrap();
        for _ in 0..(100 * 60) {
            let out = learner.update([20.0, 0.0, 0.0]);
            assert!(!out.still && !out.learning);
        }
        assert_eq!(learner.offset_dps(), [0.0; AXES]);
    }

    #[test]
    fn a_slow_turn_the_gyro_cannot_see_is_caught_by_the_accelerometer() {
        let mut learner = StillnessLearner::new(&settings()).unwrap();
        for i in 0..(100 * 30) {
            // 2.5 °/s about X: within the rate threshold, but gravity swings through the Y-Z plane.
            let angle = (2.5 * i as f32 / 100.0).to_radians();
            learner.accelerometer([0.0, angle.sin(), angle.cos()]);
            let out = learner.update([2.5, 0.0, 0.0]);
            assert!(!out.learning, "learned at sample {i}");
        }
    }

    #[test]
    fn bad_settings_are_named() {
        let bad = StillnessSettings {
            time_constant_s: 0.0,
            ..settings()
        };
        let err = StillnessLearner::new(&bad).unwrap_err();
        assert_eq!(err.field, "time_constant_s");
        let bad = StillnessSettings {
            still_for_s: f32::NAN,
            ..settings()
        };
        assert_eq!(
            StillnessLearner::new(&bad).unwrap_err().field,
            "still_for_s"
        );
    }

    #[test]
    fn a_non_finite_sample_passes_and_stops_the_timer() {
        let mut learner = StillnessLearner::new(&settings()).unwrap();
        for _ in 0..600 {
            learner.update([0.01; AXES]);
        }
        let before = learner.offset_dps();
        let out = learner.update([f32::NAN, 0.0, 0.0]);
        assert!(!out.still && out.rate_dps[0].is_nan());
        assert_eq!(learner.offset_dps(), before);
        assert!(!learner.update([0.01; AXES]).learning);
    }
}
