//! Field motion: rotations with still gaps, the way an instrument on a vehicle or in a hand moves.
//!
//! The unit is otherwise held static in every simulated series; a field series with a motion
//! profile adds a body rate to the gyro and turns gravity in the accelerometer while it rotates.
//! Each activation starts with a still gap (the vehicle waits after switch-on), then rotations
//! about random axes at random rates alternate with still gaps until switch-off. A profile with
//! no gaps (`still_s = [0, 0]`) rotates throughout.
//!
//! The rotations are drawn up front from their own seeded stream, so switching motion on changes
//! no other draw of the campaign. [`true_rate`] gives the body rate an evaluation subtracts:
//! truth, like [`crate::truth`], never for fitting.

use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The motion profile of field activations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Motion {
    /// Duration of one rotation (s), uniform.
    pub rotation_s: [f64; 2],
    /// Magnitude of the body rate during a rotation (°/s), uniform; about a random axis.
    pub rate_dps: [f64; 2],
    /// Still gap before each rotation (s), uniform; `[0, 0]` for none.
    pub still_s: [f64; 2],
}

impl Default for Motion {
    fn default() -> Self {
        Self {
            rotation_s: [2.0, 8.0],
            rate_dps: [10.0, 90.0],
            still_s: [5.0, 40.0],
        }
    }
}

/// One rotation at a constant body rate over samples `start..end` of an activation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// First sample.
    pub start: u32,
    /// One past the last sample.
    pub end: u32,
    /// Body rate per axis (°/s).
    pub rate_dps: [f64; 3],
}

fn uniform(r: &mut ChaCha8Rng, range: [f64; 2]) -> f64 {
    range[0] + (range[1] - range[0]) * r.random::<f64>()
}

/// The rotations of one activation of `samples` samples at `sample_rate_hz`, in order.
pub fn plan(
    motion: &Motion,
    samples: u32,
    sample_rate_hz: u32,
    r: &mut ChaCha8Rng,
) -> Vec<Rotation> {
    let fs = f64::from(sample_rate_hz);
    let to_samples = |s: f64| ((s * fs).round() as u32).max(1);
    let mut out = Vec::new();
    let mut at = 0u32;
    while at < samples {
        let still = uniform(r, motion.still_s);
        if still > 0.0 {
            at = at.saturating_add(to_samples(still));
        }
        let length = to_samples(uniform(r, motion.rotation_s));
        let magnitude = uniform(r, motion.rate_dps);
        let axis: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(r));
        let norm = axis.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
        if at >= samples {
            break;
        }
        let end = at.saturating_add(length).min(samples);
        out.push(Rotation {
            start: at,
            end,
            rate_dps: axis.map(|v| magnitude * v / norm),
        });
        at = end;
    }
    out
}

/// The body rate at sample `i` (°/s): the rotation covering it, or zero while still.
pub fn true_rate(rotations: &[Rotation], i: u32) -> [f64; 3] {
    rotations
        .iter()
        .find(|rot| (rot.start..rot.end).contains(&i))
        .map_or([0.0; 3], |rot| rot.rate_dps)
}

/// [`true_rate`] for increasing `i`, walking `cursor` forward instead of searching.
pub(crate) fn rate_from(rotations: &[Rotation], cursor: &mut usize, i: u32) -> [f64; 3] {
    while rotations.get(*cursor).is_some_and(|rot| rot.end <= i) {
        *cursor += 1;
    }
    match rotations.get(*cursor) {
        Some(rot) if rot.start <= i => rot.rate_dps,
        _ => [0.0; 3],
    }
}

/// Gravity in the body frame after the body turned at `rate_dps` for `dt_s`: the body frame turns
/// by ω·dt, so a fixed vector turns by −ω·dt in it (Rodrigues' formula, exact for a constant rate).
pub fn turn_gravity(gravity: [f64; 3], rate_dps: [f64; 3], dt_s: f64) -> [f64; 3] {
    let w = rate_dps.map(f64::to_radians);
    let speed = w.iter().map(|v| v * v).sum::<f64>().sqrt();
    if speed == 0.0 {
        return gravity;
    }
    let k = w.map(|v| v / speed);
    let angle = -speed * dt_s;
    let (sin, cos) = angle.sin_cos();
    let dot: f64 = k.iter().zip(&gravity).map(|(a, b)| a * b).sum();
    let cross = [
        k[1] * gravity[2] - k[2] * gravity[1],
        k[2] * gravity[0] - k[0] * gravity[2],
        k[0] * gravity[1] - k[1] * gravity[0],
    ];
    std::array::from_fn(|a| gravity[a] * cos + cross[a] * sin + k[a] * dot * (1.0 - cos))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    #[test]
    fn rotations_alternate_with_gaps_within_their_ranges() {
        let m = Motion::default();
        let mut r = rng::stream(7, &[rng::tag("motion")]);
        let rotations = plan(&m, 180_000, 1000, &mut r);
        assert!(rotations.len() >= 3, "{rotations:?}");
        let mut previous_end = 0;
        for rot in &rotations {
            let gap = rot.start - previous_end;
            assert!((4_999..=40_001).contains(&gap), "gap {gap}");
            assert!(rot.end <= 180_000 && rot.end > rot.start);
            let speed = rot.rate_dps.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((10.0 - 1e-9..=90.0 + 1e-9).contains(&speed), "{speed}");
            previous_end = rot.end;
        }
        assert_eq!(true_rate(&rotations, 0), [0.0; 3]);
        let first = rotations[0];
        assert_eq!(true_rate(&rotations, first.start), first.rate_dps);
    }

    #[test]
    fn no_gaps_rotates_throughout() {
        let m = Motion {
            still_s: [0.0, 0.0],
            ..Motion::default()
        };
        let mut r = rng::stream(7, &[rng::tag("motion")]);
        let rotations = plan(&m, 60_000, 1000, &mut r);
        assert_eq!(rotations[0].start, 0);
        for pair in rotations.windows(2) {
            assert_eq!(pair[0].end, pair[1].start);
        }
        assert_eq!(rotations.last().map(|r| r.end), Some(60_000));
    }

    #[test]
    fn a_quarter_turn_about_x_moves_gravity_from_z_to_y() {
        let g = turn_gravity([0.0, 0.0, 1.0], [90.0, 0.0, 0.0], 1.0);
        // The body turns +90° about X: a vector fixed in space turns −90° in the body frame.
        assert!(
            (g[0]).abs() < 1e-12 && (g[1] - 1.0).abs() < 1e-12 && g[2].abs() < 1e-12,
            "{g:?}"
        );
    }
}
