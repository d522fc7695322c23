//! Stage 2: ambient temperature. Locates the switch-on temperature among the calibration ambients,
//! once per activation.

use crate::interp::{bracket, lerp, Bracket};

/// The two calibration ambients that bracket the switch-on temperature, and the blend between them.
///
/// The paper indexes ambient by the temperature at switch-on; after a short off-time that is the
/// ambient plus residual heat, which is how the calibration saw it too.
/// Outside the calibrated range the nearest ambient is used (clamp) and, beyond the margin, flagged.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AmbientPosition {
    /// Index of the lower (or only) ambient.
    pub lo: u8,
    /// Index of the upper ambient (`lo` when clamped or exactly on a calibration ambient).
    pub hi: u8,
    /// Weight of the upper ambient, in [0, 1).
    pub weight: f32,
    /// The switch-on temperature is outside the calibrated range by more than the margin.
    pub out_of_range: bool,
}

impl AmbientPosition {
    /// Locates `celsius` among strictly increasing calibration ambients given by `ambient(item)`.
    pub fn locate<T>(
        ambients: &[T],
        celsius: f32,
        margin_celsius: f32,
        ambient: impl Fn(&T) -> f32,
    ) -> Self {
        let first = ambients.first().map_or(f32::NAN, &ambient);
        let last = ambients.last().map_or(f32::NAN, &ambient);
        let last_index = ambients.len().saturating_sub(1) as u8;
        match bracket(ambients, celsius, ambient) {
            Bracket::Below => Self {
                lo: 0,
                hi: 0,
                weight: 0.0,
                out_of_range: !(celsius >= first - margin_celsius),
            },
            Bracket::Inside { lo, fraction } => {
                let lo = lo as u8;
                Self {
                    lo,
                    hi: if fraction > 0.0 { lo.saturating_add(1) } else { lo },
                    weight: fraction,
                    out_of_range: false,
                }
            }
            Bracket::Above => Self {
                lo: last_index,
                hi: last_index,
                weight: 0.0,
                out_of_range: !(celsius <= last + margin_celsius),
            },
        }
    }

    /// Blends per-ambient values `at_lo` and `at_hi` by this position's weight.
    #[inline]
    pub fn blend(&self, at_lo: f32, at_hi: f32) -> f32 {
        lerp(at_lo, at_hi, self.weight)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn locate(celsius: f32) -> AmbientPosition {
        AmbientPosition::locate(&[30.0_f32, 40.0], celsius, 0.5, |a| *a)
    }

    #[test]
    fn between_ambients_blends() {
        let p = locate(33.0);
        assert_eq!((p.lo, p.hi, p.out_of_range), (0, 1, false));
        assert!((p.weight - 0.3).abs() < 1e-6);
    }

    #[test]
    fn clamps_outside_and_flags_beyond_margin() {
        assert_eq!(
            locate(29.7),
            AmbientPosition {
                lo: 0,
                hi: 0,
                weight: 0.0,
                out_of_range: false
            }
        );
        assert!(locate(29.0).out_of_range);
        assert!(!locate(40.4).out_of_range);
        let p = locate(45.0);
        assert_eq!((p.lo, p.hi, p.out_of_range), (1, 1, true));
        assert!(locate(f32::NAN).out_of_range);
    }
}
