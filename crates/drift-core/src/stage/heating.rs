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

/// One curve around the current time: its blended point at the segment's low reference time and
/// the change from there to the high one. Kept as a change rather than as the second point
/// because every sample needs `lo + (hi − lo) · fraction`: the subtraction is done once per
/// segment, with the same bits.
type Knots = [CurvePoint; 2];

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

    /// Curve `c`'s blended knots around the current time.
    #[inline(always)]
    fn knots(&self, c: usize) -> Knots {
        let lo = self.knot(c, self.time.lo);
        let hi = self.knot(c, self.time.hi);
        [
            lo,
            CurvePoint {
                rise_celsius: hi.rise_celsius - lo.rise_celsius,
                k_dps_per_celsius: hi.k_dps_per_celsius - lo.k_dps_per_celsius,
            },
        ]
    }
}

/// A curve's point at the current time from its knots (stage 1), the rise scaled before the first
/// reference time: `lerp` with the change precomputed. The only place a point is made, so cached
/// and fresh knots give the same bits.
#[inline(always)]
fn at_time(time: &TimePosition, [lo, change]: Knots) -> CurvePoint {
    let fraction = time.fraction;
    CurvePoint {
        rise_celsius: time.rise_scale * (lo.rise_celsius + change.rise_celsius * fraction),
        k_dps_per_celsius: lo.k_dps_per_celsius + change.k_dps_per_celsius * fraction,
    }
}

/// The correlation `k` at `rise_celsius` for the blend at `ambient` of `ambients`, read at `time`,
/// and whether the rise lies beyond the curves' span by more than `margin_celsius` (then the
/// nearest curve's `k` is used: clamp).
///
/// The bracket is the last curve whose rise does not exceed the current one. `cache` keeps the
/// previous sample's bracket with its two curves' knots for the current reference-time segment
/// (the caller empties it when the segment changes):
/// while time stays in the segment and the rise in the bracket (almost every sample), a sample
/// costs two time interpolations, one division and no table access. Otherwise the search walks
/// the blended curves from the cached bracket and refills the cache. The cache only saves work: a
/// fresh or any valid cache gives the same bits.
#[inline(always)]
pub fn k_at<const R: usize, const C: usize>(
    ambients: &[AmbientCurves<R, C>],
    ambient: &AmbientPosition,
    time: TimePosition,
    rise_celsius: f32,
    margin_celsius: f32,
    cache: &mut BracketCache,
) -> (f32, bool) {
    if cache.valid {
        let lower = at_time(&time, cache.knots[0]);
        let upper = at_time(&time, cache.knots[1]);
        let below = rise_celsius < lower.rise_celsius;
        if (!below || cache.curve == 0) && (cache.top || rise_celsius < upper.rise_celsius) {
            return interpolate(lower, upper, cache.top, rise_celsius, margin_celsius);
        }
    }
    search(
        &BlendedCurves::new(ambients, ambient, time),
        rise_celsius,
        margin_celsius,
        cache,
    )
}

/// `k` inside the bracket `lower`..`upper` (`top`: `lower` is the last curve, no upper), clamped
/// below the first curve and above the last.
#[inline(always)]
fn interpolate(
    lower: CurvePoint,
    upper: CurvePoint,
    top: bool,
    rise_celsius: f32,
    margin_celsius: f32,
) -> (f32, bool) {
    if rise_celsius < lower.rise_celsius {
        let beyond = rise_celsius < lower.rise_celsius - margin_celsius;
        (lower.k_dps_per_celsius, beyond)
    } else if !top {
        let fraction =
            (rise_celsius - lower.rise_celsius) / (upper.rise_celsius - lower.rise_celsius);
        let k = lerp(lower.k_dps_per_celsius, upper.k_dps_per_celsius, fraction);
        (k, false)
    } else {
        let beyond = rise_celsius > lower.rise_celsius + margin_celsius;
        (lower.k_dps_per_celsius, beyond)
    }
}

/// The cache-miss path of [`k_at`]: walks the blended curves from the cached bracket to the one
/// that holds the rise, keeps its knots, and interpolates.
#[inline(never)]
fn search<const R: usize>(
    curves: &BlendedCurves<'_, R>,
    rise_celsius: f32,
    margin_celsius: f32,
    cache: &mut BracketCache,
) -> (f32, bool) {
    let time = &curves.time;
    let count = curves.lower.len();
    let last = count.saturating_sub(1);
    let mut lo = usize::from(cache.curve).min(last);
    let mut lower_knots = curves.knots(lo);
    let mut lower = at_time(time, lower_knots);
    while lower.rise_celsius > rise_celsius && lo > 0 {
        lo = lo.saturating_sub(1);
        lower_knots = curves.knots(lo);
        lower = at_time(time, lower_knots);
    }
    let mut upper_knots = curves.knots(lo.saturating_add(1));
    let mut upper = at_time(time, upper_knots);
    while lo < last && upper.rise_celsius <= rise_celsius {
        lo = lo.saturating_add(1);
        (lower_knots, lower) = (upper_knots, upper);
        upper_knots = curves.knots(lo.saturating_add(1));
        upper = at_time(time, upper_knots);
    }
    let top = lo >= last;
    *cache = BracketCache {
        valid: true,
        curve: saturating_u8(lo),
        top,
        knots: [lower_knots, upper_knots],
    };
    interpolate(lower, upper, top, rise_celsius, margin_celsius)
}

const MISSING: CurvePoint = CurvePoint {
    rise_celsius: f32::NAN,
    k_dps_per_celsius: f32::NAN,
};

/// Stage 3's search state, kept per axis between samples: the bracketing curve and its blended
/// knots for the current reference-time segment.
///
/// Belongs to the tables, ambient and reference-time segment it was filled with; `power_on` and
/// a change of segment empty it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BracketCache {
    /// Whether the knots below were filled (for the current segment).
    pub valid: bool,
    /// Lower curve of the bracket.
    pub curve: u8,
    /// The lower curve is the last one (there is no upper curve; the rise is clamped above it).
    pub top: bool,
    /// Per curve of the bracket (`curve`, `curve + 1`): the blended point at the segment's low
    /// reference time, and its change to the high one.
    pub knots: [[CurvePoint; 2]; 2],
}
