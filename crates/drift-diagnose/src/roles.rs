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
//! - **diagnosis** (when the analyst names data for it: `--diagnose-on` set points of the campaign,
//!   or `--diagnosis-data`): half of the named series — ranked on, terms fitted and guarded on —
//!   while the other half stays held out and judges; the loop then runs again with the halves
//!   swapped ([`Roles::diagnose_on`]), so that every named series is judged once by a loop that
//!   never saw it;
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
    /// The half of the analyst's diagnosis series this loop ranks, fits and guards on
    /// ([`Roles::diagnose_on`]); the other half is held out.
    pub diagnosis: Vec<&'a Segment>,
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

    /// Moves half of the series in `named` (the analyst's diagnosis data: the held-out activations
    /// at the `--diagnose-on` set points, field and protocol, or a separate source) to the
    /// diagnosis role and holds out the other half: `half` 0 or 1 picks which. Series are known by
    /// unit, nominal set point, kind and index ([`series_key`]), never by a measured temperature,
    /// and alternate between the halves in that order, so both halves span the same set points
    /// and kinds.
    pub fn diagnose_on(&mut self, named: impl Fn(&Segment) -> bool, half: usize) {
        let (mut named, kept): (Vec<&Segment>, Vec<&Segment>) = std::mem::take(&mut self.held_out)
            .into_iter()
            .partition(|s| named(s));
        let mut keys: Vec<SeriesKey> = named.iter().map(|s| series_key(s)).collect();
        keys.sort();
        keys.dedup();
        let in_half = |s: &Segment| {
            keys.binary_search(&series_key(s))
                .is_ok_and(|i| i % 2 == half % 2)
        };
        let (diagnosis, judged): (Vec<&Segment>, Vec<&Segment>) =
            named.drain(..).partition(|s| in_half(s));
        self.diagnosis.extend(diagnosis);
        self.held_out = kept;
        self.held_out.extend(judged);
    }

    /// The activations the extended model's coefficients are fitted and its terms guarded on: the
    /// training ones and the diagnosis half.
    pub fn fitting(&self) -> Vec<&'a Segment> {
        self.training
            .iter()
            .chain(&self.diagnosis)
            .copied()
            .collect()
    }

    /// The activations the diagnosis ranks candidates on: the training and selection ones when
    /// there are any (so the held-out ones stay unseen until the before/after), else the ones not
    /// judged on (with a separate evaluation source), else every activation the fit did not see.
    pub fn diagnosed(&self) -> Vec<&'a Segment> {
        if self.training.is_empty() && self.selection.is_empty() && self.diagnosis.is_empty() {
            if self.not_judged.is_empty() {
                self.held_out.clone()
            } else {
                self.not_judged.clone()
            }
        } else {
            self.training
                .iter()
                .chain(&self.selection)
                .chain(&self.diagnosis)
                .copied()
                .collect()
        }
    }
}

/// What identifies a series: unit, nominal set point (m°C), kind and series index.
pub type SeriesKey = (String, i64, &'static str, u32);

/// The series `segment` belongs to ([`SeriesKey`]): the recording's nominal set point, not the
/// ambient at switch-on, which in a ramped field session differs at every activation.
pub fn series_key(segment: &Segment) -> SeriesKey {
    let labels = &segment.labels;
    (
        labels.unit_id.clone(),
        (labels.nominal_set_point_celsius() * 1000.0).round() as i64,
        labels.series_kind.as_str(),
        labels.series,
    )
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use drift_recording::SegmentLabels;

    use super::*;

    /// A one-sample activation: only its labels matter to the split.
    fn activation(kind: SeriesKind, at_switch_on: f64, session: Option<f64>) -> Segment {
        in_series(kind, at_switch_on, session, 1)
    }

    fn in_series(
        kind: SeriesKind,
        at_switch_on: f64,
        session: Option<f64>,
        series: u32,
    ) -> Segment {
        Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: at_switch_on,
                session_set_point_celsius: session,
                series_kind: kind,
                series,
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

    /// The analyst's diagnosis series at +33 °C (ramped: every switch-on logs another set point)
    /// split into halves of whole series, alternating; the calibration's roles stay as they were,
    /// and the other half is held out.
    #[test]
    fn diagnosis_series_split_into_halves_of_whole_series() {
        let mut segments = vec![
            in_series(SeriesKind::Protocol, 30.0, Some(30.0), 1),
            in_series(SeriesKind::Field, 30.4, Some(30.0), 1),
        ];
        for series in 1..=4 {
            for k in 0..5 {
                segments.push(in_series(
                    SeriesKind::Field,
                    31.0 + f64::from(k) * 0.7 + f64::from(series) * 0.01,
                    Some(33.0),
                    series,
                ));
            }
        }
        segments.push(in_series(SeriesKind::Protocol, 33.0, Some(33.0), 1));
        let named = |s: &Segment| is_one_of(s.labels.nominal_set_point_celsius(), &[33.0]);
        let halves: Vec<Roles> = (0..2)
            .map(|half| {
                let mut roles = Roles::split(&segments, &[30.0, 40.0]);
                roles.diagnose_on(named, half);
                roles
            })
            .collect();
        for (half, roles) in halves.iter().enumerate() {
            assert_eq!(roles.calibration.len(), 1);
            assert_eq!(roles.training.len(), 1);
            let keys = |v: &[&Segment]| -> Vec<SeriesKey> {
                let mut k: Vec<SeriesKey> = v.iter().map(|s| series_key(s)).collect();
                k.dedup();
                k
            };
            let diagnosed = keys(&roles.diagnosis);
            // Whole series: five activations per field series in this half.
            let field = roles
                .diagnosis
                .iter()
                .filter(|s| s.labels.series_kind == SeriesKind::Field)
                .count();
            assert_eq!(field % 5, 0, "half {half}: {field}");
            let other = &halves[1 - half];
            assert!(diagnosed
                .iter()
                .all(|k| !keys(&other.diagnosis).contains(k)));
            assert_eq!(roles.diagnosis.len() + other.diagnosis.len(), 21);
            assert_eq!(roles.held_out.len(), 21 - roles.diagnosis.len());
            assert!(roles.fitting().len() == 1 + roles.diagnosis.len());
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
