//! Stage 1: time since switch-on. Locates the current time among the table's reference times.

use crate::interp::{bracket, value_at, Bracket};

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
    /// Locates `since_power_on_ms` among strictly increasing `reference_ms`.
    ///
    /// Time stays an integer (milliseconds) until it is made relative to the bracketing reference
    /// time, so hours of operation lose no resolution.
    pub fn locate(reference_ms: &[u32], since_power_on_ms: u32) -> Self {
        let first = reference_ms.first().copied().unwrap_or(0);
        let last_index = reference_ms.len().saturating_sub(1);
        // Offsets from the first reference time fit f32 exactly up to 2^24 ms (4.6 h); beyond the
        // last reference time the position is held, so larger offsets never reach the division.
        let held = |past_last| TimePosition {
            lo: if past_last { last_index } else { 0 },
            hi: if past_last { last_index } else { 0 },
            fraction: 0.0,
            rise_scale: 1.0,
            past_last,
        };
        if since_power_on_ms < first {
            return TimePosition {
                rise_scale: since_power_on_ms as f32 / first as f32,
                ..held(false)
            };
        }
        let x = since_power_on_ms.saturating_sub(first) as f32;
        match bracket(reference_ms, x, |&t| t.saturating_sub(first) as f32) {
            Bracket::Below => held(false),
            Bracket::Inside { lo, fraction } => TimePosition {
                lo,
                hi: if fraction > 0.0 { lo.saturating_add(1) } else { lo },
                fraction,
                rise_scale: 1.0,
                past_last: false,
            },
            Bracket::Above => held(true),
        }
    }

    /// A curve's value (`k` or rise) at this time, by linear interpolation between reference times.
    #[inline]
    pub fn value(&self, values: &[f32]) -> f32 {
        value_at(values, self.lo, self.hi, self.fraction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REFS: [u32; 3] = [2_000, 5_000, 30_000];

    #[test]
    fn before_first_reference_scales_rise_and_holds_k() {
        let p = TimePosition::locate(&REFS, 500);
        assert_eq!((p.lo, p.hi, p.fraction, p.past_last), (0, 0, 0.0, false));
        assert_eq!(p.rise_scale, 0.25);
        assert_eq!(TimePosition::locate(&REFS, 0).rise_scale, 0.0);
    }

    #[test]
    fn between_and_on_reference_times() {
        let p = TimePosition::locate(&REFS, 3_500);
        assert_eq!((p.lo, p.hi, p.fraction, p.rise_scale), (0, 1, 0.5, 1.0));
        let p = TimePosition::locate(&REFS, 5_000);
        assert_eq!((p.lo, p.hi, p.fraction), (1, 1, 0.0));
        let p = TimePosition::locate(&REFS, 30_000);
        assert_eq!((p.lo, p.hi, p.fraction, p.past_last), (2, 2, 0.0, false));
    }

    #[test]
    fn past_last_reference_holds_and_flags_even_after_hours() {
        for ms in [30_001, 3_600_000, u32::MAX] {
            let p = TimePosition::locate(&REFS, ms);
            assert_eq!((p.lo, p.hi, p.past_last), (2, 2, true));
        }
    }
}
