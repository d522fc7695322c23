//! Stage 1: time since switch-on. Locates the current time among the table's reference times.

use crate::error::saturating_u8;
use crate::interp::lerp;
use crate::table::CurvePoint;

/// Where the current time since switch-on falls among the reference times, shared by every curve of
/// an axis (the curves are all sampled at the same reference times).
///
/// Policy outside the reference times:
/// - **Before the first reference time** the correlation `k = g / rise` is undefined (rise ≈ 0 at
///   switch-on), so each curve's `k` is held at its value at the first reference time, and each
///   curve's rise is taken as linear from 0 at switch-on to its value at the first reference time
///   (`rise_scale` < 1). The drift `k · rise` then starts from zero with the measured rise, and the
///   heating-dynamics stage compares like with like instead of flagging every early sample.
/// - **After the last reference time** `k` and the curve rises are held at their last values and the
///   sample is flagged [`Flags::PAST_LAST_REFERENCE`](crate::Flags::PAST_LAST_REFERENCE); the drift is
///   still `k · rise` with the measured rise, so it keeps following the temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimePosition {
    /// Reference-time index below (or at) the current time.
    pub lo: usize,
    /// Reference-time index above the current time (`lo` when held at an end).
    pub hi: usize,
    /// Fraction of the way from `lo` to `hi`, in [0, 1).
    pub fraction: f32,
    /// Factor applied to the curves' rises: `since_power_on / first reference time` before the first
    /// reference time, 1 after it.
    pub rise_scale: f32,
    /// The time is past the last reference time.
    pub past_last: bool,
}

impl TimePosition {
    /// Locates `since_power_on_ms` among strictly increasing `reference_ms`, starting the search at
    /// `hint` (the previous sample's segment, updated here): time moves forward a millisecond at a
    /// time, so the search usually ends where it starts.
    ///
    /// Time stays an integer (milliseconds) until it is made relative to the bracketing reference
    /// time, so hours of operation lose no resolution.
    pub fn locate(reference_ms: &[u32], since_power_on_ms: u32, hint: &mut u8) -> Self {
        let last = reference_ms.len().saturating_sub(1);
        let at = |j: usize| reference_ms.get(j).copied().unwrap_or(u32::MAX);
        let first = at(0);
        if since_power_on_ms < first {
            *hint = 0;
            return TimePosition {
                lo: 0,
                hi: 0,
                fraction: 0.0,
                // Both below 2^24 in practice (reference times are seconds to minutes), so exact.
                rise_scale: since_power_on_ms as f32 / first as f32,
                past_last: false,
            };
        }
        let mut lo = usize::from(*hint).min(last);
        while lo > 0 && at(lo) > since_power_on_ms {
            lo = lo.saturating_sub(1);
        }
        while lo < last && at(lo.saturating_add(1)) <= since_power_on_ms {
            lo = lo.saturating_add(1);
        }
        *hint = saturating_u8(lo);
        let offset = since_power_on_ms.saturating_sub(at(lo));
        if lo == last {
            return TimePosition {
                lo,
                hi: lo,
                fraction: 0.0,
                rise_scale: 1.0,
                past_last: offset > 0,
            };
        }
        let hi = lo.saturating_add(1);
        // Offsets within one segment are far below 2^24 ms, so the conversion is exact.
        let span = at(hi).saturating_sub(at(lo));
        TimePosition {
            lo,
            hi: if offset > 0 { hi } else { lo },
            fraction: offset as f32 / span as f32,
            rise_scale: 1.0,
            past_last: false,
        }
    }

    /// A curve's point (rise and `k`) at this time, by linear interpolation between reference
    /// times; `None` if the curve is too short (only for tables that skipped validation).
    #[inline(always)]
    pub fn point(&self, points: &[CurvePoint]) -> Option<CurvePoint> {
        let (lo, hi) = (points.get(self.lo)?, points.get(self.hi)?);
        Some(CurvePoint {
            rise_celsius: lerp(lo.rise_celsius, hi.rise_celsius, self.fraction),
            k_dps_per_celsius: lerp(lo.k_dps_per_celsius, hi.k_dps_per_celsius, self.fraction),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REFS: [u32; 3] = [2_000, 5_000, 30_000];

    #[test]
    fn before_first_reference_scales_rise_and_holds_k() {
        let p = TimePosition::locate(&REFS, 500, &mut 0);
        assert_eq!((p.lo, p.hi, p.fraction, p.past_last), (0, 0, 0.0, false));
        assert_eq!(p.rise_scale, 0.25);
        assert_eq!(TimePosition::locate(&REFS, 0, &mut 0).rise_scale, 0.0);
    }

    #[test]
    fn between_and_on_reference_times() {
        let p = TimePosition::locate(&REFS, 3_500, &mut 2);
        assert_eq!((p.lo, p.hi, p.fraction, p.rise_scale), (0, 1, 0.5, 1.0));
        let p = TimePosition::locate(&REFS, 5_000, &mut 0);
        assert_eq!((p.lo, p.hi, p.fraction), (1, 1, 0.0));
        let p = TimePosition::locate(&REFS, 30_000, &mut 1);
        assert_eq!((p.lo, p.hi, p.fraction, p.past_last), (2, 2, 0.0, false));
    }

    #[test]
    fn past_last_reference_holds_and_flags_even_after_hours() {
        for ms in [30_001, 3_600_000, u32::MAX] {
            let p = TimePosition::locate(&REFS, ms, &mut 0);
            assert_eq!((p.lo, p.hi, p.past_last), (2, 2, true));
        }
    }
}
