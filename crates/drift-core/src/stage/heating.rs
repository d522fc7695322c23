//! Stage 3: heating dynamics. The unit does not know how long it was off; the current temperature
//! rise picks the two stored activation curves whose rises bracket it, and `k` is interpolated
//! between them by rise.

use crate::interp::lerp;
use crate::stage::since_power_on::TimePosition;
use crate::table::Curve;

/// The correlation `k` (°/s per °C) at the current time and rise, from one ambient's curves.
///
/// The curves are stored ordered by rise at every reference time; a positive blend of two ordered
/// sequences is ordered too, so the curves' rises at the current time are ordered and a binary
/// search finds the bracket. Outside the curves' span the nearest curve's `k` is used, and the second
/// value says whether the rise is beyond the span by more than `margin_celsius`.
pub fn k_at<const R: usize>(
    curves: &[Curve<R>],
    time: &TimePosition,
    rise_celsius: f32,
    margin_celsius: f32,
) -> (f32, bool) {
    let rise_of = |curve: &Curve<R>| time.rise_scale * time.value(&curve.rise_celsius);
    let k_of = |curve: &Curve<R>| time.value(&curve.k_dps_per_celsius);
    let above = curves.partition_point(|curve| rise_of(curve) <= rise_celsius);
    let lower = above.checked_sub(1).and_then(|lo| curves.get(lo));
    match (lower, curves.get(above)) {
        (Some(lo), Some(hi)) => {
            let (rise_lo, rise_hi) = (rise_of(lo), rise_of(hi));
            let fraction = (rise_celsius - rise_lo) / (rise_hi - rise_lo);
            (lerp(k_of(lo), k_of(hi), fraction), false)
        }
        (None, Some(lowest)) => (
            k_of(lowest),
            rise_celsius < rise_of(lowest) - margin_celsius,
        ),
        (Some(highest), None) => (
            k_of(highest),
            rise_celsius > rise_of(highest) + margin_celsius,
        ),
        (None, None) => (f32::NAN, true),
    }
}
