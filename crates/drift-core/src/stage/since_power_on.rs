//! Stage 1: time since switch-on. Locates the current time among the table's reference times.
//!
//! Policy outside the reference times:
//! - **Before the first reference time** the correlation `k = g / rise` is undefined (rise ≈ 0 at
//!   switch-on), so each curve's `k` is held at its value at the first reference time, and each
//!   curve's rise is taken as linear from 0 at switch-on to its value at the first reference time.
//!   The drift `k · rise` then starts from zero with the measured rise, and the heating-dynamics
//!   stage compares like with like instead of flagging every early sample.
//! - **After the last reference time** `k` and the curve rises are held at their last values and
//!   the sample is flagged [`Flags::PAST_LAST_REFERENCE`](crate::Flags::PAST_LAST_REFERENCE); the
//!   drift is still `k · rise` with the measured rise, so it keeps following the temperature.
//!
//! Time stays an integer (milliseconds) until it is made relative to the segment's start, so hours
//! of operation lose no resolution.

use crate::error::saturating_u8;

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
///
/// `PastLast`'s discriminant is the bit of
/// [`Flags::PAST_LAST_REFERENCE`](crate::Flags::PAST_LAST_REFERENCE) and no other kind's shares
/// it: every sample reads its flag as one mask, not a comparison and a select (3 instructions per
/// axis on the Cortex-M4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(u8)]
pub enum SegmentKind {
    /// Before the first reference time: rises scaled, `k` held.
    #[default]
    BeforeFirst,
    /// Between two reference times.
    Between,
    /// Exactly on the last reference time.
    OnLast,
    /// Past the last reference time: held and flagged.
    PastLast = 4,
}

/// A time inside its segment, as stage 3 reads the curves there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moment {
    /// `(t − start) / length` of the segment, in [0, 1); 0 from the last reference time on. Before
    /// the first reference time it is also the factor on the curves' rises (`t / first reference
    /// time`), and the knots' change over the segment is 0, so it moves nothing else.
    pub fraction: f32,
    /// The time is before the first reference time: rises are scaled by `fraction`.
    pub before_first: bool,
}

impl Segment {
    /// Locates `since_power_on_ms` among strictly increasing `reference_ms`, starting the search at
    /// `hint` (the previous segment's low index): time moves forward, so the search usually ends one
    /// step from where it starts. A missing reference time reads as `u32::MAX` (only for tables
    /// that skipped validation). Inlined into the model's out-of-line miss path: one call per
    /// segment, not two.
    #[inline(always)]
    pub fn locate(reference_ms: &[u32], since_power_on_ms: u32, hint: u8) -> Self {
        let last = reference_ms.len().saturating_sub(1);
        let at = |j: usize| reference_ms.get(j).copied().unwrap_or(u32::MAX);
        let first = at(0);
        if since_power_on_ms < first {
            return Self {
                start_ms: 0,
                len_ms: first,
                // Reference times are seconds to minutes: below 2^24, so exact in f32.
                per_ms: 1.0 / first as f32,
                lo: 0,
                kind: SegmentKind::BeforeFirst,
            };
        }
        let mut lo = usize::from(hint).min(last);
        while lo > 0 && at(lo) > since_power_on_ms {
            lo = lo.saturating_sub(1);
        }
        // Forward over the times after `lo` (one bounds check for the walk, not one per step); the
        // first one past the time ends the segment.
        let mut start_ms = at(lo);
        let mut end_ms = None;
        for &time in reference_ms.get(lo.saturating_add(1)..).unwrap_or_default() {
            if time > since_power_on_ms {
                end_ms = Some(time);
                break;
            }
            start_ms = time;
            lo = lo.saturating_add(1);
        }
        let (start_ms, len_ms, per_ms, kind) = match end_ms {
            Some(end_ms) => {
                let span = end_ms.saturating_sub(start_ms);
                // Spans are far below 2^24 ms, so exact in f32.
                (start_ms, span, 1.0 / span as f32, SegmentKind::Between)
            }
            None if since_power_on_ms == start_ms => (start_ms, 1, 0.0, SegmentKind::OnLast),
            None => {
                // Past the last reference time: from the next millisecond to the end of time.
                let start_ms = start_ms.saturating_add(1);
                let len_ms = u32::MAX.saturating_sub(start_ms).saturating_add(1);
                (start_ms, len_ms, 0.0, SegmentKind::PastLast)
            }
        };
        Self {
            start_ms,
            len_ms,
            per_ms,
            lo: saturating_u8(lo),
            kind,
        }
    }

    /// Reference-time index of the segment's high end (`lo` when there is none).
    pub fn hi(&self) -> u8 {
        if self.kind == SegmentKind::Between {
            self.lo.saturating_add(1)
        } else {
            self.lo
        }
    }

    /// Where `since_power_on_ms` falls in this segment, if it lies in it.
    #[inline(always)]
    pub fn moment(&self, since_power_on_ms: u32) -> Option<Moment> {
        // Unsigned: a time before `start_ms` wraps to a large offset and misses too.
        let offset = since_power_on_ms.wrapping_sub(self.start_ms);
        if offset >= self.len_ms {
            return None;
        }
        Some(Moment {
            // Offsets within one segment are far below 2^24 ms, so the conversion is exact (and
            // before the first reference time the offset is the time since switch-on).
            fraction: offset as f32 * self.per_ms,
            before_first: self.kind == SegmentKind::BeforeFirst,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REFS: [u32; 3] = [2_000, 5_000, 30_000];

    fn at(ms: u32, hint: u8) -> (Segment, Moment) {
        let segment = Segment::locate(&REFS, ms, hint);
        (segment, segment.moment(ms).unwrap())
    }

    #[test]
    fn before_first_reference_scales_rise() {
        let (segment, moment) = at(500, 2);
        assert_eq!(
            (segment.lo, segment.hi(), segment.kind),
            (0, 0, SegmentKind::BeforeFirst)
        );
        assert_eq!(moment.fraction, 0.25);
        assert!(moment.before_first);
        assert_eq!(at(0, 0).1.fraction, 0.0);
    }

    #[test]
    fn between_and_on_reference_times() {
        let (segment, moment) = at(3_500, 2);
        assert_eq!((segment.lo, segment.hi(), moment.fraction), (0, 1, 0.5));
        assert!(!moment.before_first);
        // On a reference time: the segment it starts, at fraction 0.
        let (segment, moment) = at(5_000, 0);
        assert_eq!((segment.lo, segment.hi(), moment.fraction), (1, 2, 0.0));
        let (segment, moment) = at(30_000, 1);
        assert_eq!(
            (segment.lo, segment.hi(), segment.kind),
            (2, 2, SegmentKind::OnLast)
        );
        assert_eq!(moment.fraction, 0.0);
    }

    #[test]
    fn past_last_reference_holds_even_after_hours() {
        for ms in [30_001, 3_600_000, u32::MAX] {
            let (segment, moment) = at(ms, 0);
            assert_eq!(
                (segment.lo, segment.hi(), segment.kind),
                (2, 2, SegmentKind::PastLast)
            );
            assert_eq!(moment.fraction, 0.0);
        }
    }

    #[test]
    fn a_segment_holds_exactly_its_times_whatever_the_hint() {
        for ms in (0..40_000).step_by(7).chain([u32::MAX, 29_999, 30_000, 1]) {
            let segment = Segment::locate(&REFS, ms, 0);
            for hint in [1, 2, 255] {
                assert_eq!(Segment::locate(&REFS, ms, hint), segment, "{ms}");
            }
            assert!(segment.moment(ms).is_some(), "{ms}");
            let end = segment.start_ms.wrapping_add(segment.len_ms);
            if segment.kind != SegmentKind::PastLast {
                assert!(segment.moment(end).is_none());
                assert_eq!(Segment::locate(&REFS, end, segment.lo).start_ms, end);
            }
            if segment.start_ms > 0 {
                assert!(segment.moment(segment.start_ms - 1).is_none());
            }
        }
    }
}
