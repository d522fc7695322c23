//! Stage 1: time since switch-on. Locates the current time among the table's reference times.

use crate::error::saturating_u8;

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

/// One stretch of time that shares its reference-time indices: before the first reference time,
/// between two reference times (the lower one included), on the last one, or past it. Located
/// once when time enters it and kept in the axis state, so that a sample in the same stretch —
/// almost every sample — costs a subtraction, a comparison and a multiplication instead of a
/// search and a division.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Segment {
    /// First millisecond of the segment.
    pub start_ms: u32,
    /// Length in ms: the segment holds `start_ms ≤ t < start_ms + len_ms` (0: empty, as a
    /// default `Segment` is; the stretch past the last reference time ends at `u32::MAX`, which
    /// it reads as its own).
    pub len_ms: u32,
    /// Reciprocal of the segment's length in ms (`1 / first reference time` before it, 0 from the
    /// last one on): the per-sample division becomes a multiplication.
    pub per_ms: f32,
    /// Reference-time index of the segment's low end.
    pub lo: u8,
    /// What the segment is.
    pub kind: SegmentKind,
}

/// Which stretch of time a [`Segment`] covers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SegmentKind {
    /// Before the first reference time: rises scaled, `k` held.
    #[default]
    BeforeFirst,
    /// Between two reference times.
    Between,
    /// Exactly on the last reference time.
    OnLast,
    /// Past the last reference time: held and flagged.
    PastLast,
}

impl Segment {
    /// Locates `since_power_on_ms` among strictly increasing `reference_ms`, starting the search at
    /// `hint` (the previous segment's low index, updated here): time moves forward, so the search
    /// usually ends one step from where it starts. A missing reference time reads as `u32::MAX`
    /// (only for tables that skipped validation). Out of line: once per segment, not per sample.
    #[inline(never)]
    pub fn locate(reference_ms: &[u32], since_power_on_ms: u32, hint: &mut u8) -> Self {
        let last = reference_ms.len().saturating_sub(1);
        let at = |j: usize| reference_ms.get(j).copied().unwrap_or(u32::MAX);
        let first = at(0);
        if since_power_on_ms < first {
            *hint = 0;
            return Self {
                start_ms: 0,
                len_ms: first,
                // Reference times are seconds to minutes: below 2^24, so exact in f32.
                per_ms: 1.0 / first as f32,
                lo: 0,
                kind: SegmentKind::BeforeFirst,
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
        let start_ms = at(lo);
        let (len_ms, per_ms, kind) = if lo < last {
            let span = at(lo.saturating_add(1)).saturating_sub(start_ms);
            // Spans are far below 2^24 ms, so exact in f32.
            (span, 1.0 / span as f32, SegmentKind::Between)
        } else if since_power_on_ms == start_ms {
            (1, 0.0, SegmentKind::OnLast)
        } else {
            // Past the last reference time: from the next millisecond to the end of time.
            let start_ms = start_ms.saturating_add(1);
            return Self {
                start_ms,
                len_ms: u32::MAX.saturating_sub(start_ms).saturating_add(1),
                per_ms: 0.0,
                lo: saturating_u8(lo),
                kind: SegmentKind::PastLast,
            };
        };
        Self {
            start_ms,
            len_ms,
            per_ms,
            lo: saturating_u8(lo),
            kind,
        }
    }

    /// The position of `since_power_on_ms` if it lies in this segment.
    #[inline(always)]
    pub fn position(&self, since_power_on_ms: u32) -> Option<TimePosition> {
        // Unsigned: a time before `start_ms` wraps to a large offset and misses too.
        let offset = since_power_on_ms.wrapping_sub(self.start_ms);
        if offset >= self.len_ms {
            return None;
        }
        // Offsets within one segment are far below 2^24 ms, so the conversion is exact (and
        // before the first reference time the offset is the time since switch-on).
        let scaled = offset as f32 * self.per_ms;
        let lo = usize::from(self.lo);
        Some(match self.kind {
            SegmentKind::BeforeFirst => TimePosition {
                lo,
                hi: lo,
                fraction: 0.0,
                rise_scale: scaled,
                past_last: false,
            },
            SegmentKind::Between => TimePosition {
                lo,
                hi: lo.saturating_add(1),
                fraction: scaled,
                rise_scale: 1.0,
                past_last: false,
            },
            SegmentKind::OnLast | SegmentKind::PastLast => TimePosition {
                lo,
                hi: lo,
                fraction: 0.0,
                rise_scale: 1.0,
                past_last: self.kind == SegmentKind::PastLast,
            },
        })
    }
}

impl TimePosition {
    /// Locates `since_power_on_ms` among strictly increasing `reference_ms`, starting the search at
    /// `hint` (the previous sample's segment, updated here).
    ///
    /// Time stays an integer (milliseconds) until it is made relative to the bracketing reference
    /// time, so hours of operation lose no resolution.
    pub fn locate(reference_ms: &[u32], since_power_on_ms: u32, hint: &mut u8) -> Self {
        Self::locate_cached(
            reference_ms,
            since_power_on_ms,
            hint,
            &mut Segment::default(),
        )
        .0
    }

    /// As [`Self::locate`], reusing `segment` when the time still lies in it and refilling it
    /// otherwise; the second value says whether it was refilled. Cached or fresh, a time gives the
    /// same bits: both go through [`Segment::position`].
    #[inline(always)]
    pub fn locate_cached(
        reference_ms: &[u32],
        since_power_on_ms: u32,
        hint: &mut u8,
        segment: &mut Segment,
    ) -> (Self, bool) {
        if let Some(position) = segment.position(since_power_on_ms) {
            return (position, false);
        }
        *segment = Segment::locate(reference_ms, since_power_on_ms, hint);
        let position = segment.position(since_power_on_ms).unwrap_or(TimePosition {
            lo: 0,
            hi: 0,
            fraction: f32::NAN,
            rise_scale: f32::NAN,
            past_last: false,
        });
        (position, true)
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
        // On a reference time: the segment it starts, at fraction 0.
        let p = TimePosition::locate(&REFS, 5_000, &mut 0);
        assert_eq!((p.lo, p.hi, p.fraction), (1, 2, 0.0));
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

    #[test]
    fn a_cached_segment_gives_the_same_bits_as_a_fresh_search() {
        let mut segment = Segment::default();
        let mut hint = 0;
        for ms in (0..40_000)
            .step_by(7)
            .chain([u32::MAX, 0, 29_999, 30_000, 1])
        {
            let (cached, _) = TimePosition::locate_cached(&REFS, ms, &mut hint, &mut segment);
            let fresh = TimePosition::locate(&REFS, ms, &mut 1);
            assert_eq!(
                (cached.lo, cached.hi, cached.past_last),
                (fresh.lo, fresh.hi, fresh.past_last)
            );
            assert_eq!(cached.fraction.to_bits(), fresh.fraction.to_bits(), "{ms}");
            assert_eq!(cached.rise_scale.to_bits(), fresh.rise_scale.to_bits());
        }
    }
}
