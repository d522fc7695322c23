//! Which activations play which part when the loop is closed, so that nothing is chosen or fitted
//! on the activations the error is finally measured on:
//!
//! - **calibration**: the paper's protocol at the calibration set points — the tables;
//! - **training**: field-like activations at the calibration set points that switch on inside the
//!   calibrated ambient range — the diagnosis ranks candidates on them, the guard admits terms on
//!   them, the terms' coefficients are fitted on them;
//! - **held out**: everything else (other set points, other sessions, and the training-like
//!   activations outside the ambient range) — the before/after is measured on them.

use drift_recording::{Segment, SeriesKind};

use crate::evaluate::{switch_on_raw, within_ambient_range};
use crate::fit::FittedUnit;
use crate::pipeline::is_one_of;
use crate::settings::FitSettings;

/// One unit's activations by role.
#[derive(Debug, Clone, Default)]
pub struct Roles<'a> {
    /// Protocol activations at the calibration set points.
    pub calibration: Vec<&'a Segment>,
    /// Field-like activations at the calibration set points (inside the ambient range once
    /// [`Roles::hold_out_outside_range`] ran).
    pub training: Vec<&'a Segment>,
    /// Everything else.
    pub held_out: Vec<&'a Segment>,
    /// How many field-like activations at the calibration set points were moved to `held_out`
    /// because they switch on outside the calibrated ambient range.
    pub outside_range: usize,
}

impl<'a> Roles<'a> {
    /// Splits one unit's activations by series kind and set point.
    pub fn split(
        segments: impl IntoIterator<Item = &'a Segment>,
        calibration_set_points: &[f64],
    ) -> Self {
        let mut roles = Self::default();
        for segment in segments {
            let at_calibration =
                is_one_of(segment.labels.set_point_celsius, calibration_set_points);
            match (at_calibration, segment.labels.series_kind) {
                (true, SeriesKind::Protocol) => roles.calibration.push(segment),
                (true, SeriesKind::Field) => roles.training.push(segment),
                _ => roles.held_out.push(segment),
            }
        }
        roles
    }

    /// Moves the training activations that switch on outside `fitted`'s calibrated ambient range
    /// (after a short off-time the switch-on temperature is above the hottest calibration
    /// ambient) to the held-out ones: the model clamps their ambient by design and flags it, and
    /// a term learnt there would learn the clamp, not the effect (and then fail between the
    /// calibration ambients).
    pub fn hold_out_outside_range(&mut self, fitted: &FittedUnit, settings: &FitSettings) {
        let (inside, outside): (Vec<&Segment>, Vec<&Segment>) = std::mem::take(&mut self.training)
            .into_iter()
            .partition(|s| within_ambient_range(&fitted.modified, switch_on_raw(s, settings)));
        self.training = inside;
        self.outside_range += outside.len();
        self.held_out.extend(outside);
    }

    /// The activations the diagnosis ranks candidates on: the training ones when there are any
    /// (so the held-out ones stay unseen until the before/after), else every activation the fit
    /// did not see.
    pub fn diagnosed(&self) -> &[&'a Segment] {
        if self.training.is_empty() {
            &self.held_out
        } else {
            &self.training
        }
    }
}
