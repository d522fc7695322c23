//! Which activations play which part when the loop is closed, so that nothing is chosen or fitted
//! on the activations the error is finally measured on:
//!
//! - **calibration**: the paper's protocol at the calibration set points — the tables;
//! - **training**: field-like activations at the calibration set points that switch on inside the
//!   calibrated ambient range — the diagnosis ranks candidates on them, the guard admits terms on
//!   them, the terms' coefficients are fitted on them;
//! - **selection** (only when the analyst names set points for it): the protocol activations at
//!   those set points, which the fit never saw — the diagnosis ranks candidates on them beside the
//!   training ones, and nothing is measured on them;
//! - **held out**: everything else (other set points, other sessions, and the training-like
//!   activations outside the ambient range) — the before/after is measured on them.

use drift_recording::{Segment, SeriesKind};

use drift_evaluate::evaluate::{switch_on_raw, within_ambient_range};
use drift_evaluate::pipeline::is_one_of;
use drift_fit::fit::FittedUnit;
use drift_fit::settings::FitSettings;

/// One unit's activations by role.
#[derive(Debug, Clone, Default)]
pub struct Roles<'a> {
    /// Protocol activations at the calibration set points.
    pub calibration: Vec<&'a Segment>,
    /// Field-like activations at the calibration set points (inside the ambient range once
    /// [`Roles::hold_out_outside_range`] ran).
    pub training: Vec<&'a Segment>,
    /// Protocol activations at set points named for the diagnosis ([`Roles::select`]).
    pub selection: Vec<&'a Segment>,
    /// Everything else.
    pub held_out: Vec<&'a Segment>,
    /// How many field-like activations at the calibration set points were moved to `held_out`
    /// because they switch on outside the calibrated ambient range.
    pub outside_range: usize,
    /// With the judging on a separate source (`closing::close_separate`): the calibration
    /// source's activations that would have been held out, and are not judged on.
    pub not_judged: Vec<&'a Segment>,
}

impl<'a> Roles<'a> {
    /// Splits one unit's activations by series kind and the set point each belongs to: the
    /// recording's nominal one ([`SegmentLabels::nominal_set_point_celsius`]), not the ambient at
    /// switch-on, which in a session with ambient ramps is almost never a calibration set point.
    ///
    /// [`SegmentLabels::nominal_set_point_celsius`]: drift_recording::SegmentLabels::nominal_set_point_celsius
    pub fn split(
        segments: impl IntoIterator<Item = &'a Segment>,
        calibration_set_points: &[f64],
    ) -> Self {
        let mut roles = Self::default();
        for segment in segments {
            let at_calibration = is_one_of(
                segment.labels.nominal_set_point_celsius(),
                calibration_set_points,
            );
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

    /// Moves the held-out protocol activations at `set_points` (none of them a calibration set
    /// point: those are the fit's) to the selection: more activations to rank candidates on, at
    /// the price of measuring nothing on them.
    pub fn select(&mut self, set_points: &[f64]) {
        let (selected, kept): (Vec<&Segment>, Vec<&Segment>) = std::mem::take(&mut self.held_out)
            .into_iter()
            .partition(|s| {
                s.labels.series_kind == SeriesKind::Protocol
                    && is_one_of(s.labels.nominal_set_point_celsius(), set_points)
            });
        self.selection.extend(selected);
        self.held_out = kept;
    }

    /// The activations the diagnosis ranks candidates on: the training and selection ones when
    /// there are any (so the held-out ones stay unseen until the before/after), else the ones not
    /// judged on (with a separate evaluation source), else every activation the fit did not see.
    pub fn diagnosed(&self) -> Vec<&'a Segment> {
        if self.training.is_empty() && self.selection.is_empty() {
            if self.not_judged.is_empty() {
                self.held_out.clone()
            } else {
                self.not_judged.clone()
            }
        } else {
            self.training
                .iter()
                .chain(&self.selection)
                .copied()
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use drift_recording::SegmentLabels;

    use super::*;

    /// A one-sample activation: only its labels matter to the split.
    fn activation(kind: SeriesKind, at_switch_on: f64, session: Option<f64>) -> Segment {
        Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: at_switch_on,
                session_set_point_celsius: session,
                series_kind: kind,
                series: 1,
                repeat: 1,
                activation: 1,
                interval_min: None,
                off_before_s: None,
            },
            sample_rate_hz: 1000,
            power_on_ns: 0,
            since_power_on: vec![0],
            rate_dps: [vec![0.0], vec![0.0], vec![0.0]],
            temperature_raw: [vec![6000], vec![6000], vec![6000]],
            temperature_scale: drift_recording::TemperatureScale::default(),
            aux: BTreeMap::new(),
        }
    }

    #[test]
    fn ramped_field_activations_take_the_role_of_their_sessions_set_point() {
        let segments = [
            activation(SeriesKind::Protocol, 30.0, Some(30.0)),
            // Switched on while the chamber ramped: 36.7 °C and 31.2 °C at switch-on, in the
            // sessions at +40 and +33 °C.
            activation(SeriesKind::Field, 36.7, Some(40.0)),
            activation(SeriesKind::Field, 31.2, Some(33.0)),
            // A ramp can pass through a calibration set point in a validation session.
            activation(SeriesKind::Field, 30.0, Some(33.0)),
            // No nominal set point recorded: the switch-on label decides.
            activation(SeriesKind::Field, 30.0, None),
        ];
        let roles = Roles::split(&segments, &[30.0, 40.0]);
        let at =
            |v: &[&Segment]| -> Vec<f64> { v.iter().map(|s| s.labels.set_point_celsius).collect() };
        assert_eq!(at(&roles.calibration), [30.0]);
        assert_eq!(at(&roles.training), [36.7, 30.0]);
        assert_eq!(at(&roles.held_out), [31.2, 30.0]);
        assert_eq!(
            roles.held_out[1].labels.session_set_point_celsius,
            Some(33.0)
        );
    }
}
