//! Closing the loop for one unit, in the data's one direction: activations by role → the
//! diagnosis of the paper model's residual → proposed terms → the guarded extended model → the
//! error before and after on the held-out activations. The command line (`gyrodrift diagnose
//! [--extend]`), the Python module and the closed-loop experiment all run this.

use drift_core::Previous;
use drift_recording::Segment;
use serde::Serialize;

use crate::diagnose::{diagnose, ActivationSeries, AxisDiagnosis, Diagnoser};
use crate::error::FitError;
use crate::evaluate::{correct_segment_after, kept_before, metric, switch_on_raw};
use crate::extend::{correct_with_terms, extend, Extended, TermPlan};
use crate::fit::FittedUnit;
use crate::roles::Roles;
use crate::settings::FitSettings;

/// One unit's loop, closed as far as its data allow.
pub struct Closed<'a> {
    /// Which activations played which part.
    pub roles: Roles<'a>,
    /// The diagnosed activations on the diagnosis grid.
    pub series: Vec<ActivationSeries>,
    /// The ranking per axis.
    pub axes: [AxisDiagnosis; 3],
    /// The terms the diagnosis proposes (significant winners the firmware can compute).
    pub proposed: TermPlan,
    /// The extended model, when asked for, when something was proposed and there are training
    /// activations to fit it on.
    pub extended: Option<Extended>,
}

/// The error of one held-out activation with the paper's model and with the extended one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BeforeAfter {
    /// The set point the activation belongs to (the recording's nominal one; with ambient ramps
    /// the ambient at switch-on differs), °C.
    pub set_point_celsius: f64,
    /// `protocol` or `field`.
    pub series_kind: &'static str,
    /// Per axis, the paper's drift metric (max − min of the 1-s mean), °/s: before, after.
    pub drift_dps: [(f64, f64); 3],
    /// Per axis, RMS of the 1-s mean, °/s: before, after.
    pub rms_dps: [(f64, f64); 3],
    /// Per axis, the drift metric with the paper's curves keyed by heating history
    /// ([`FittedUnit::by_history`], fed what firmware would have kept of the unit's previous
    /// activation), °/s.
    pub by_history_drift_dps: [f64; 3],
    /// Per axis, the RMS with the curves keyed by heating history, °/s.
    pub by_history_rms_dps: [f64; 3],
}

/// Whether stage 3 keyed by heating history ([`FittedUnit::by_history`]) replaces the paper's
/// lookup by rise on one axis: only where the fit found the calibration curves crossing on that
/// axis (the rise no longer names the history), and only if on the training activations (field-like
/// use at the calibration set points; never the held-out ones) it leaves less drift than the
/// paper's lookup — the guard's rule for a term, applied to a lookup.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stage3Choice {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Whether the fit found crossing curves on this axis ([`FittedUnit::crossings`]).
    pub curves_cross: bool,
    /// Training activations compared (0 when the curves do not cross: nothing is tried).
    pub training_activations: usize,
    /// Their mean drift with the paper's lookup, °/s.
    pub training_drift_by_rise_dps: f64,
    /// Their mean drift keyed by history, °/s.
    pub training_drift_by_history_dps: f64,
    /// The choice.
    pub keyed_by_history: bool,
}

/// Splits `segments` (one unit's) by role, diagnoses the paper model `fitted` on the training
/// activations (or, without any, on every activation the fit did not see), and with `extend`
/// fits the guarded extended model.
pub fn close<'a>(
    fitted: &FittedUnit,
    segments: impl IntoIterator<Item = &'a Segment>,
    calibration_set_points: &[f64],
    settings: &FitSettings,
    extend_model: bool,
) -> Result<Closed<'a>, FitError> {
    let mut roles = Roles::split(segments, calibration_set_points);
    roles.hold_out_outside_range(fitted, settings);
    let diagnoser = Diagnoser::new(fitted, &roles.calibration, settings)?;
    let series: Vec<ActivationSeries> = roles
        .diagnosed()
        .iter()
        .map(|s| diagnoser.series(s))
        .collect();
    let axes = diagnose(&series);
    let proposed = TermPlan::choose(&axes);
    let extended = if extend_model && !proposed.terms.is_empty() && !roles.training.is_empty() {
        Some(extend(
            fitted,
            &proposed,
            &roles.calibration,
            &roles.training,
            settings,
        )?)
    } else {
        None
    };
    Ok(Closed {
        roles,
        series,
        axes,
        proposed,
        extended,
    })
}

impl Closed<'_> {
    /// The unit's activations in the order its firmware lived them, with what it kept before
    /// each (`clock`: it also knows a full cool-down), as indices into calibration, training and
    /// held-out activations in that order.
    fn lived(
        &self,
        fitted: &FittedUnit,
        settings: &FitSettings,
        clock: bool,
    ) -> Vec<[Previous; 3]> {
        let roles = &self.roles;
        let life: Vec<&Segment> = roles
            .calibration
            .iter()
            .chain(&roles.training)
            .chain(&roles.held_out)
            .copied()
            .collect();
        kept_before(&life, settings, &fitted.by_history.settings, clock)
    }

    /// Per axis, whether stage 3 keyed by history replaces the paper's lookup ([`Stage3Choice`]),
    /// decided on the training activations.
    pub fn choose_stage3(
        &self,
        fitted: &FittedUnit,
        settings: &FitSettings,
        clock: bool,
    ) -> [Stage3Choice; 3] {
        let cross = |axis: usize| fitted.crossings.iter().any(|c| c.axis == axis);
        let training = &self.roles.training;
        let window = settings.lowpass_window_samples;
        let mut sums = [(0.0, 0.0); 3];
        if (0..3).any(cross) {
            let kept = self.lived(fitted, settings, clock);
            let kept_training = &kept[self.roles.calibration.len()..][..training.len()];
            for (segment, previous) in training.iter().zip(kept_training) {
                let on = switch_on_raw(segment, settings);
                let (rise, _) = metric(
                    &correct_segment_after(&fitted.modified, segment, on, None).0,
                    window,
                );
                let (history, _) = metric(
                    &correct_segment_after(&fitted.by_history, segment, on, Some(previous)).0,
                    window,
                );
                for a in 0..3 {
                    sums[a].0 += rise[a];
                    sums[a].1 += history[a];
                }
            }
        }
        std::array::from_fn(|a| {
            let n = if cross(a) { training.len() } else { 0 };
            let mean = |sum: f64| if n == 0 { f64::NAN } else { sum / n as f64 };
            let (by_rise, by_history) = (mean(sums[a].0), mean(sums[a].1));
            Stage3Choice {
                axis: ["X", "Y", "Z"][a],
                curves_cross: cross(a),
                training_activations: n,
                training_drift_by_rise_dps: by_rise,
                training_drift_by_history_dps: by_history,
                keyed_by_history: n > 0 && by_history < by_rise,
            }
        })
    }

    /// The terms the guard admitted (empty without an extended model).
    pub fn admitted(&self) -> TermPlan {
        self.extended
            .as_ref()
            .map_or_else(TermPlan::default, |e| e.plan.clone())
    }

    /// The error before (paper's model `fitted`) and after (the extended model; the paper's model
    /// when nothing was admitted) on every held-out activation.
    ///
    /// The history-keyed model runs through the unit's whole life in order, as its firmware would
    /// have lived it; `clock`: the firmware also knows when the unit cooled fully
    /// ([`crate::evaluate::kept_before`]).
    pub fn before_after(
        &self,
        fitted: &FittedUnit,
        settings: &FitSettings,
        clock: bool,
    ) -> Vec<BeforeAfter> {
        let plan = self.admitted();
        let window = settings.lowpass_window_samples;
        // The unit's whole life in order, as its firmware would have lived it: every activation
        // passes what it kept on to the next.
        let roles = &self.roles;
        let kept = self.lived(fitted, settings, clock);
        let kept_held_out = &kept[roles.calibration.len() + roles.training.len()..];
        roles
            .held_out
            .iter()
            .zip(kept_held_out)
            .map(|(segment, previous)| {
                let on = switch_on_raw(segment, settings);
                let (history_drift, history_rms) = metric(
                    &correct_segment_after(&fitted.by_history, segment, on, Some(previous)).0,
                    window,
                );
                let (drift_before, rms_before) = metric(
                    &correct_with_terms(&fitted.modified, &plan, segment, on),
                    window,
                );
                let (drift_after, rms_after) = match &self.extended {
                    Some(e) if !e.plan.terms.is_empty() => {
                        metric(&correct_with_terms(&e.tables, &plan, segment, on), window)
                    }
                    _ => (drift_before, rms_before),
                };
                BeforeAfter {
                    set_point_celsius: segment.labels.nominal_set_point_celsius(),
                    series_kind: segment.labels.series_kind.as_str(),
                    drift_dps: std::array::from_fn(|a| (drift_before[a], drift_after[a])),
                    rms_dps: std::array::from_fn(|a| (rms_before[a], rms_after[a])),
                    by_history_drift_dps: history_drift,
                    by_history_rms_dps: history_rms,
                }
            })
            .collect()
    }
}
