//! Stage 3: heating dynamics. The unit does not know how long it was off; the current temperature
//! rise picks the two stored activation curves whose rises bracket it, and `k` is interpolated
//! between them by rise.

use crate::error::saturating_u8;
use crate::interp::lerp;
use crate::stage::ambient::AmbientPosition;
use crate::stage::since_power_on::TimePosition;
use crate::table::{AmbientCurves, Curve, CurvePoint};

/// The curves of the two bracketing calibration ambients, blended curve by curve (stage 2), read at
/// the current time (stage 1).
///
/// Curve `c` of one ambient corresponds to curve `c` of every other (same count, each ordered by
/// rise), so a blend of two ordered sets is ordered too and stage 3 can search it.
pub struct BlendedCurves<'a, const R: usize> {
    lower: &'a [Curve<R>],
    upper: &'a [Curve<R>],
    weight: f32,
    time: TimePosition,
}

impl<'a, const R: usize> BlendedCurves<'a, R> {
    /// The blend at `ambient` of `ambients`, read at `time`. Missing ambients read as no curves.
    #[inline(always)]
    pub fn new<const C: usize>(
        ambients: &'a [AmbientCurves<R, C>],
        ambient: &AmbientPosition,
        time: TimePosition,
    ) -> Self {
        let curves = |i: u8| {
            ambients
                .get(usize::from(i))
                .map_or(&[][..], |a| a.curves.as_slice())
        };
        Self {
            lower: curves(ambient.lo),
            upper: curves(ambient.hi),
            weight: ambient.weight,
            time,
        }
    }

    /// Curve `c` at the current time and ambient (rise scaled before the first reference time);
    /// NaN if missing (only for tables that skipped validation).
    #[inline(always)]
    fn point(&self, c: usize) -> CurvePoint {
        let at_time = |curves: &[Curve<R>]| {
            curves
                .get(c)
                .and_then(|curve| self.time.point(&curve.points))
        };
        let missing = CurvePoint {
            rise_celsius: f32::NAN,
            k_dps_per_celsius: f32::NAN,
        };
        let Some(lower) = at_time(self.lower) else {
            return missing;
        };
        let blended = if self.weight > 0.0 {
            let Some(upper) = at_time(self.upper) else {
                return missing;
            };
            CurvePoint {
                rise_celsius: lerp(lower.rise_celsius, upper.rise_celsius, self.weight),
                k_dps_per_celsius: lerp(
                    lower.k_dps_per_celsius,
                    upper.k_dps_per_celsius,
                    self.weight,
                ),
            }
        } else {
            lower
        };
        CurvePoint {
            rise_celsius: self.time.rise_scale * blended.rise_celsius,
            ..blended
        }
    }

    /// The correlation `k` at the current rise, and whether the rise lies beyond the curves' span by
    /// more than `margin_celsius` (then the nearest curve's `k` is used: clamp).
    ///
    /// The bracket is the last curve whose rise does not exceed the current one. The search starts
    /// from `hint` (the previous sample's bracket, updated here): the rise changes slowly, so it
    /// usually costs only the two curve evaluations the interpolation needs anyway. Any hint gives
    /// the same result.
    #[inline(always)]
    pub fn k_at(&self, rise_celsius: f32, margin_celsius: f32, hint: &mut u8) -> (f32, bool) {
        let last = self.lower.len().saturating_sub(1);
        let mut lo = usize::from(*hint).min(last);
        let mut lower = self.point(lo);
        while lower.rise_celsius > rise_celsius && lo > 0 {
            lo = lo.saturating_sub(1);
            lower = self.point(lo);
        }
        let mut upper = self.point(lo.saturating_add(1));
        while lo < last && upper.rise_celsius <= rise_celsius {
            lo = lo.saturating_add(1);
            lower = upper;
            upper = self.point(lo.saturating_add(1));
        }
        *hint = saturating_u8(lo);
        if rise_celsius < lower.rise_celsius || self.lower.is_empty() {
            let beyond = rise_celsius < lower.rise_celsius - margin_celsius;
            (lower.k_dps_per_celsius, beyond)
        } else if lo < last {
            let fraction =
                (rise_celsius - lower.rise_celsius) / (upper.rise_celsius - lower.rise_celsius);
            let k = lerp(lower.k_dps_per_celsius, upper.k_dps_per_celsius, fraction);
            (k, false)
        } else {
            let beyond = rise_celsius > lower.rise_celsius + margin_celsius;
            (lower.k_dps_per_celsius, beyond)
        }
    }
}
