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

    /// Curve `c` blended between the two ambients (stage 2) at reference-time index `j`; NaN if
    /// missing (only for tables that skipped validation).
    #[inline(always)]
    fn knot(&self, c: usize, j: usize) -> CurvePoint {
        let at = |curves: &[Curve<R>]| curves.get(c).and_then(|curve| curve.points.get(j)).copied();
        match at(self.lower) {
            Some(lower) if self.weight > 0.0 => match at(self.upper) {
                Some(upper) => CurvePoint {
                    rise_celsius: lerp(lower.rise_celsius, upper.rise_celsius, self.weight),
                    k_dps_per_celsius: lerp(
                        lower.k_dps_per_celsius,
                        upper.k_dps_per_celsius,
                        self.weight,
                    ),
                },
                None => MISSING,
            },
            Some(lower) => lower,
            None => MISSING,
        }
    }

    /// Curve `c`'s two blended knots around the current time.
    #[inline(always)]
    fn knots(&self, c: usize) -> [CurvePoint; 2] {
        [self.knot(c, self.time.lo), self.knot(c, self.time.hi)]
    }

    /// A curve's point at the current time from its two knots (stage 1), the rise scaled before the
    /// first reference time. The only place a point is made, so cached and fresh knots give the
    /// same bits.
    #[inline(always)]
    fn at_time(&self, [lo, hi]: [CurvePoint; 2]) -> CurvePoint {
        let fraction = self.time.fraction;
        CurvePoint {
            rise_celsius: self.time.rise_scale * lerp(lo.rise_celsius, hi.rise_celsius, fraction),
            k_dps_per_celsius: lerp(lo.k_dps_per_celsius, hi.k_dps_per_celsius, fraction),
        }
    }

    /// Curve `c` at the current time and ambient.
    #[inline(always)]
    fn point(&self, c: usize) -> CurvePoint {
        self.at_time(self.knots(c))
    }

    /// The correlation `k` at the current rise, and whether the rise lies beyond the curves' span by
    /// more than `margin_celsius` (then the nearest curve's `k` is used: clamp).
    ///
    /// The bracket is the last curve whose rise does not exceed the current one. The search starts
    /// from the previous sample's bracket, kept in `cache` with the blended knots of its two curves
    /// for the current reference-time segment: while time stays in the segment and the rise in the
    /// bracket (almost every sample), a sample costs two time interpolations and no table lookup.
    /// Otherwise the search walks the table and refills the cache. The cache only saves work: a
    /// fresh or any valid cache gives the same bits.
    #[inline(always)]
    pub fn k_at(
        &self,
        rise_celsius: f32,
        margin_celsius: f32,
        cache: &mut BracketCache,
    ) -> (f32, bool) {
        let count = self.lower.len();
        let last = count.saturating_sub(1);
        let key = [saturating_u8(self.time.lo), saturating_u8(self.time.hi)];
        let mut lo = usize::from(cache.curve).min(last);
        if !(cache.valid && cache.segment == key && usize::from(cache.curve) == lo) {
            cache.knots = [self.knots(lo), self.knots(lo.saturating_add(1))];
        }
        let mut lower = self.at_time(cache.knots[0]);
        let mut upper = self.at_time(cache.knots[1]);
        let inside = (lower.rise_celsius <= rise_celsius || lo == 0)
            && (lo >= last || rise_celsius < upper.rise_celsius);
        if !inside {
            while lower.rise_celsius > rise_celsius && lo > 0 {
                lo = lo.saturating_sub(1);
                lower = self.point(lo);
            }
            upper = self.point(lo.saturating_add(1));
            while lo < last && upper.rise_celsius <= rise_celsius {
                lo = lo.saturating_add(1);
                lower = upper;
                upper = self.point(lo.saturating_add(1));
            }
            cache.knots = [self.knots(lo), self.knots(lo.saturating_add(1))];
        }
        *cache = BracketCache {
            valid: true,
            segment: key,
            curve: saturating_u8(lo),
            knots: cache.knots,
        };
        if rise_celsius < lower.rise_celsius || count == 0 {
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

const MISSING: CurvePoint = CurvePoint {
    rise_celsius: f32::NAN,
    k_dps_per_celsius: f32::NAN,
};

/// Stage 3's search state, kept per axis between samples: the bracketing curve and its blended
/// knots for the current reference-time segment.
///
/// Belongs to the tables and ambient it was filled with; `power_on` resets it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BracketCache {
    /// Whether the knots below were filled.
    pub valid: bool,
    /// Reference-time indices (low, high) the knots were read at.
    pub segment: [u8; 2],
    /// Lower curve of the bracket.
    pub curve: u8,
    /// Blended knots: `[curve, curve + 1]` × `[segment low, segment high]`.
    pub knots: [[CurvePoint; 2]; 2],
}
