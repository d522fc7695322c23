//! The recording side of gyrodrift's data flow: recording → **segments** → fitted tables →
//! corrector → residual → report.
//!
//! A [`Segment`] is one activation (switch-on to switch-off) with its protocol labels. The
//! simulator writes recordings; the fitter and the evaluation read segments; neither needs the
//! other.

mod segment;

pub use segment::{AuxChannel, Segment, SegmentLabels, SeriesKind, RAW_PER_CELSIUS};
