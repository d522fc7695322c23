//! Stage 3: heating dynamics. The unit does not know how long it was off; the current temperature
//! rise picks the two stored activation curves whose rises bracket it, and `k` is interpolated
//! between them by rise. A table keyed by history instead reads the two curves whose histories
//! bracket the activation's residual heat at switch-on ([`by_history`]).

use crate::interp::lerp;
use crate::stage::since_power_on::{Moment, Segment};
use crate::table::{AmbientCurves, Curve, CurvePoint};

/// One curve around the current time: its blended point at the segment's low reference time and
/// the change from there to the high one. Kept as a change rather than as the second point
/// because every sample needs `lo + (hi − lo) · fraction`: the subtraction is done once per
/// segment, with the same bits.
pub(crate) type Knots = [CurvePoint; 2];

/// Stage 3's cache, kept per axis between samples, is the knots of the bracket's two curves for the
/// current segment (`[lower, upper]`) and the bracket's lower curve, or this value when the rise is
/// above the last curve (no upper curve: `k` is clamped). A sentinel rather than a flag of its own:
/// a unit's state stays within 256 bytes.
/// Capacities above 255 are unsupported anyway; a lower curve at 255 or beyond is cached as 254,
/// which only makes the next search start lower.
pub(crate) const TOP: u8 = u8::MAX;

const MISSING: CurvePoint = CurvePoint {
    rise_celsius: f32::NAN,
    k_dps_per_celsius: f32::NAN,
};

/// The curves of the two bracketing calibration ambients, blended curve by curve (stage 2), read
/// around the current segment's reference times (stage 1).
///
/// Curve `c` of one ambient corresponds to curve `c` of every other (same count, each ordered by
/// rise), so a blend of two ordered sets is ordered too and stage 3 can search it.
pub(crate) struct BlendedCurves<'a, const R: usize> {
    lower: &'a [Curve<R>],
    upper: &'a [Curve<R>],
    weight: f32,
    time_lo: usize,
    time_hi: usize,
}

impl<'a, const R: usize> BlendedCurves<'a, R> {
    /// The blend of ambients `ambient_lo` and the next one by `weight` (0: `ambient_lo` alone), read
    /// at `segment`'s reference times. Missing ambients read as no curves.
    #[inline(always)]
    pub(crate) fn new<const C: usize>(
        ambients: &'a [AmbientCurves<R, C>],
        ambient_lo: u8,
        weight: f32,
        segment: &Segment,
    ) -> Self {
        let curves = |i: u8| {
            ambients
                .get(usize::from(i))
                .map_or(&[][..], |a| a.curves.as_slice())
        };
        Self {
            lower: curves(ambient_lo),
            upper: curves(ambient_lo.saturating_add(1)),
            weight,
            time_lo: usize::from(segment.lo),
            time_hi: usize::from(segment.hi()),
        }
    }

    /// Curve `c`'s blended knots around the current time; NaN where missing (only for tables that
    /// skipped validation). The ambient weight is tested once per curve, not per point: with no
    /// weight the upper ambient is not read (its curves may be missing: clamped to the last one).
    #[inline(always)]
    fn knots(&self, c: usize) -> Knots {
        let points =
            |curves: &'a [Curve<R>]| curves.get(c).map_or(&[][..], |k| k.points.as_slice());
        let at = |points: &[CurvePoint], j: usize| points.get(j).copied().unwrap_or(MISSING);
        let lower = points(self.lower);
        let (mut lo, mut hi) = (at(lower, self.time_lo), at(lower, self.time_hi));
        if self.weight > 0.0 {
            let upper = points(self.upper);
            let blend = |lower: CurvePoint, upper: CurvePoint| CurvePoint {
                rise_celsius: lerp(lower.rise_celsius, upper.rise_celsius, self.weight),
                k_dps_per_celsius: lerp(
                    lower.k_dps_per_celsius,
                    upper.k_dps_per_celsius,
                    self.weight,
                ),
            };
            lo = blend(lo, at(upper, self.time_lo));
            hi = blend(hi, at(upper, self.time_hi));
        }
        [
            lo,
            CurvePoint {
                rise_celsius: hi.rise_celsius - lo.rise_celsius,
                k_dps_per_celsius: hi.k_dps_per_celsius - lo.k_dps_per_celsius,
            },
        ]
    }

    fn count(&self) -> usize {
        self.lower.len()
    }
}

/// A curve's point at `moment` from its knots (stage 1): `lerp` with the change precomputed, the
/// rise scaled before the first reference time. With [`at_time_scaled`] (the same arithmetic), the
/// only place a point is made, so cached and fresh knots give the same bits.
#[inline(always)]
fn at_time(moment: Moment, [lo, change]: Knots) -> CurvePoint {
    let fraction = moment.fraction;
    let rise = lo.rise_celsius + change.rise_celsius * fraction;
    CurvePoint {
        rise_celsius: if moment.before_first {
            fraction * rise
        } else {
            rise
        },
        k_dps_per_celsius: lo.k_dps_per_celsius + change.k_dps_per_celsius * fraction,
    }
}

/// [`at_time`] with the rise's factor chosen once per search (`fraction` before the first reference
/// time, else 1): the same bits (`1 · rise` is `rise`), one multiplication per curve instead of a
/// test and a select of the kept flag.
#[inline(always)]
fn at_time_scaled(fraction: f32, rise_scale: f32, [lo, change]: Knots) -> CurvePoint {
    CurvePoint {
        rise_celsius: rise_scale * (lo.rise_celsius + change.rise_celsius * fraction),
        k_dps_per_celsius: lo.k_dps_per_celsius + change.k_dps_per_celsius * fraction,
    }
}

/// `k` at `rise_celsius` from the cached bracket (`knots`, `curve`), if the rise still lies in it,
/// and whether the rise lies beyond the curves' span by more than `margin_celsius` (then the
/// nearest curve's `k` is used: clamp). Valid only for the segment the bracket was filled in; the
/// caller searches again when the segment changes. Almost every sample ends here: two time
/// interpolations, one division and no table access.
#[inline(always)]
pub(crate) fn cached_k(
    [lower_knots, upper_knots]: &[Knots; 2],
    curve: u8,
    moment: Moment,
    rise_celsius: f32,
    margin_celsius: f32,
) -> Option<(f32, bool)> {
    if curve == TOP {
        let [lo, change] = *lower_knots;
        // Keyed by history (the blend's knots carry a NaN rise, see `by_history`): `k` alone, as
        // `at_time` makes it; every rise comparison below would be false, so nothing is flagged.
        if lo.rise_celsius.is_nan() {
            let k = lo.k_dps_per_celsius + change.k_dps_per_celsius * moment.fraction;
            return Some((k, false));
        }
        // Above the last curve; a rise back below it searches again.
        let lower = at_time(moment, *lower_knots);
        if rise_celsius < lower.rise_celsius {
            return None;
        }
        return Some(above_last(lower, rise_celsius, margin_celsius));
    }
    let lower = at_time(moment, *lower_knots);
    if rise_celsius < lower.rise_celsius {
        return (curve == 0).then(|| below_first(lower, rise_celsius, margin_celsius));
    }
    let upper = at_time(moment, *upper_knots);
    (rise_celsius < upper.rise_celsius).then(|| (between(lower, upper, rise_celsius), false))
}

/// The bracket for `rise_celsius` among `curves` at `moment`: the last curve whose rise does not
/// exceed it (the first one if none), walked to from the cached `curve` (which only saves work:
/// any starting curve gives the same bracket). Refills the cache and returns what [`cached_k`]
/// returns. Inlined into the caller's out-of-line miss path: one call per miss, not two.
#[inline(always)]
pub(crate) fn search<const R: usize>(
    curves: &BlendedCurves<'_, R>,
    moment: Moment,
    rise_celsius: f32,
    margin_celsius: f32,
    knots: &mut [Knots; 2],
    curve: &mut u8,
) -> (f32, bool) {
    let (fraction, rise_scale) = (
        moment.fraction,
        if moment.before_first {
            moment.fraction
        } else {
            1.0
        },
    );
    let point = |knots: Knots| at_time_scaled(fraction, rise_scale, knots);
    let last = curves.count().saturating_sub(1);
    let mut lo = usize::from(*curve).min(last);
    let mut lower_knots = curves.knots(lo);
    let mut lower = point(lower_knots);
    while lower.rise_celsius > rise_celsius && lo > 0 {
        lo = lo.saturating_sub(1);
        lower_knots = curves.knots(lo);
        lower = point(lower_knots);
    }
    let mut upper_knots = curves.knots(lo.saturating_add(1));
    let mut upper = point(upper_knots);
    while lo < last && upper.rise_celsius <= rise_celsius {
        lo = lo.saturating_add(1);
        (lower_knots, lower) = (upper_knots, upper);
        upper_knots = curves.knots(lo.saturating_add(1));
        upper = point(upper_knots);
    }
    let top = lo >= last;
    *knots = [lower_knots, upper_knots];
    *curve = if top {
        TOP
    } else {
        // Clamped before the conversion, which then cannot fail: one comparison, not three.
        u8::try_from(lo.min(usize::from(TOP - 1))).unwrap_or(TOP - 1)
    };
    interpolate(lower, upper, top, rise_celsius, margin_celsius)
}

/// Stage 3 of a table keyed by history: `k` at `moment` from curves `history_lo` and the next one,
/// blended by `history_weight` (fixed for the activation). Refills the lower cached knots (`cache`)
/// so that [`cached_k`] serves the rest of the segment with no change to the paper's path: the
/// cached knots are the blend's, with a NaN rise (every rise comparison there is false, so it
/// returns the cached `k`, unflagged, as for a rise above the last curve) under the `TOP`
/// sentinel, which also keeps it from reading the upper knots.
#[inline(always)]
pub(crate) fn by_history<const R: usize>(
    curves: &BlendedCurves<'_, R>,
    moment: Moment,
    history_lo: u8,
    history_weight: f32,
    cache: &mut Knots,
    curve: &mut u8,
) -> f32 {
    let lo = usize::from(history_lo);
    let [lower, lower_change] = curves.knots(lo);
    let blend = |lower: f32, upper: f32| {
        if history_weight > 0.0 {
            lerp(lower, upper, history_weight)
        } else {
            // Also when there is no next curve (clamped to the last history): its NaN stays out.
            lower
        }
    };
    let [upper, upper_change] = if history_weight > 0.0 {
        curves.knots(lo.saturating_add(1))
    } else {
        [lower, lower_change]
    };
    let blended = [
        CurvePoint {
            rise_celsius: f32::NAN,
            k_dps_per_celsius: blend(lower.k_dps_per_celsius, upper.k_dps_per_celsius),
        },
        CurvePoint {
            rise_celsius: 0.0,
            k_dps_per_celsius: blend(
                lower_change.k_dps_per_celsius,
                upper_change.k_dps_per_celsius,
            ),
        },
    ];
    *cache = blended;
    *curve = TOP;
    at_time(moment, blended).k_dps_per_celsius
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
        below_first(lower, rise_celsius, margin_celsius)
    } else if !top {
        (between(lower, upper, rise_celsius), false)
    } else {
        above_last(lower, rise_celsius, margin_celsius)
    }
}

/// Below the first curve: its `k` (clamp), and whether the rise is below it by more than the
/// margin.
#[inline(always)]
fn below_first(first: CurvePoint, rise_celsius: f32, margin_celsius: f32) -> (f32, bool) {
    let beyond = rise_celsius < first.rise_celsius - margin_celsius;
    (first.k_dps_per_celsius, beyond)
}

/// Above the last curve: its `k` (clamp), and whether the rise is above it by more than the
/// margin.
#[inline(always)]
fn above_last(last: CurvePoint, rise_celsius: f32, margin_celsius: f32) -> (f32, bool) {
    let beyond = rise_celsius > last.rise_celsius + margin_celsius;
    (last.k_dps_per_celsius, beyond)
}

/// `k` interpolated by rise between two curves.
#[inline(always)]
fn between(lower: CurvePoint, upper: CurvePoint, rise_celsius: f32) -> f32 {
    let fraction = (rise_celsius - lower.rise_celsius) / (upper.rise_celsius - lower.rise_celsius);
    lerp(lower.k_dps_per_celsius, upper.k_dps_per_celsius, fraction)
}
