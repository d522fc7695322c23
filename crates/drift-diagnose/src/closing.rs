//! Closing the loop for one unit, in the data's one direction: activations by role → stage 3's
//! lookup chosen per axis (by rise, the paper's, or by heating history) → the initial bias chosen
//! per axis (the paper's, or with the warm starts') → the diagnosis of that model's residual →
//! proposed terms → the guarded extended model → the error before and after on the held-out
//! activations. The command line (`gyrodrift diagnose [--extend]`), the Python module and the
//! closed-loop experiment all run this.

use drift_core::{Previous, SwitchOn};
use drift_recording::Segment;
use rayon::prelude::*;
use serde::Serialize;

use crate::diagnose::{diagnose, ActivationSeries, AxisDiagnosis, Diagnoser};
use crate::extend::{correct_with_terms, extend, Extended, TermPlan};
use crate::keying::Keying;
use crate::roles::Roles;
use crate::statistics::paired_choice;
use crate::switch_on_rate::{fit_switch_on_rate, SwitchOnRateFit};
use crate::warm_start::{self, WarmStartChoice};
use drift_evaluate::evaluate::{
    correct_segment_after, kept_before, metric, profile, switch_on_raw,
};
use drift_fit::error::FitError;
use drift_fit::fit::FittedUnit;
use drift_fit::settings::FitSettings;

/// One unit's loop, closed as far as its data allow.
pub struct Closed<'a> {
    /// Which activations played which part.
    pub roles: Roles<'a>,
    /// Stage 3's lookup per axis of the loop's model, chosen on the training activations.
    pub stage3: [Stage3Choice; 3],
    /// Whether the initial bias of warm starts is taken per axis, chosen on the training
    /// activations after stage 3.
    pub warm_start: [WarmStartChoice; 3],
    /// Both choices with what firmware kept before each of the unit's activations.
    pub keying: Keying,
    /// The diagnosed activations on the diagnosis grid.
    pub series: Vec<ActivationSeries>,
    /// The ranking per axis: what is left behind the loop's model.
    pub axes: [AxisDiagnosis; 3],
    /// The ranking per axis behind the paper's model (stage 3 by rise, the paper's initial bias),
    /// on the same activations: what the paper's model lacked, which the loop's choices and terms
    /// then answer. The same as `axes` when the loop kept the paper's model.
    pub paper_axes: [AxisDiagnosis; 3],
    /// The terms the diagnosis proposes (significant winners the firmware can compute).
    pub proposed: TermPlan,
    /// Per axis, the rate at switch-on as measured on the calibration: where the diagnosis starts
    /// its rate candidates and the extended model its rate term (whose extension holds where the
    /// filter starts: without the heating for the element's rate).
    pub switch_on_rate: [SwitchOnRateFit; 3],
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
    /// Per axis, the mean of the corrected output, °/s: before, after — the activation's offset,
    /// which the drift metric cannot see.
    pub mean_dps: [(f64, f64); 3],
    /// Per axis, the residual heat at switch-on as firmware estimates it from what it kept of the
    /// unit's previous activation (`drift_core::SwitchOn::estimate`; 0 when nothing was kept), °C.
    pub residual_heat_celsius: [f64; 3],
    /// The off-time before the activation, as the recording labels it (the bench's clock; the
    /// firmware does not know it), s.
    pub off_before_s: Option<f64>,
}

/// Bins of [`Closed::profiles`], s since switch-on: fine over the first 30 s, where a warm start's
/// transient fades, coarser after; the last bin runs to the activation's end.
pub const PROFILE_EDGES_S: [f64; 13] = [
    0.0,
    1.0,
    2.0,
    4.0,
    7.0,
    10.0,
    15.0,
    20.0,
    30.0,
    45.0,
    60.0,
    90.0,
    f64::INFINITY,
];

/// Where within one held-out activation the loop's residual sits ([`Closed::profiles`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Profile {
    /// The set point the activation belongs to, °C.
    pub set_point_celsius: f64,
    /// `protocol` or `field`.
    pub series_kind: &'static str,
    /// The off-time before the activation, as the recording labels it, s.
    pub off_before_s: Option<f64>,
    /// Per axis and [`PROFILE_EDGES_S`] bin, the loop's 1-s residual there less its activation
    /// mean, °/s ([`drift_evaluate::evaluate::profile`]).
    pub after_dps: [Vec<f64>; 3],
}

/// The groups [`mean_profiles`] averages in, in order: the protocol, and the field by the off-time
/// before (a warm start's transient depends on it).
pub const PROFILE_GROUPS: [&str; 5] = [
    "protocol",
    "field, off < 90 s",
    "field, off 90–600 s",
    "field, off ≥ 600 s",
    "field, off-time not recorded",
];

impl Profile {
    /// The one of [`PROFILE_GROUPS`] this activation belongs to.
    pub fn group(&self) -> &'static str {
        let [protocol, short, medium, long, unknown] = PROFILE_GROUPS;
        match (self.series_kind, self.off_before_s) {
            ("protocol", _) => protocol,
            (_, None) => unknown,
            (_, Some(off)) if off < 90.0 => short,
            (_, Some(off)) if off < 600.0 => medium,
            (_, Some(_)) => long,
        }
    }
}

/// The mean profile of each group of `profiles` that has any ([`PROFILE_GROUPS`] order): the group,
/// its activations and per axis and bin the mean over them (NaN where none reaches the bin).
pub fn mean_profiles(profiles: &[&Profile]) -> Vec<(&'static str, usize, [Vec<f64>; 3])> {
    PROFILE_GROUPS
        .iter()
        .filter_map(|&group| {
            let members: Vec<&&Profile> = profiles.iter().filter(|p| p.group() == group).collect();
            if members.is_empty() {
                return None;
            }
            let means = std::array::from_fn(|axis| {
                (0..PROFILE_EDGES_S.len() - 1)
                    .map(|bin| {
                        let values: Vec<f64> = members
                            .iter()
                            .filter_map(|p| p.after_dps[axis].get(bin).copied())
                            .filter(|v| v.is_finite())
                            .collect();
                        if values.is_empty() {
                            f64::NAN
                        } else {
                            values.iter().sum::<f64>() / values.len() as f64
                        }
                    })
                    .collect()
            });
            Some((group, members.len(), means))
        })
        .collect()
}

/// The bins of [`PROFILE_EDGES_S`] as labels ("0–1 s", …, "90 s–end").
pub fn profile_bin_labels() -> Vec<String> {
    PROFILE_EDGES_S
        .windows(2)
        .map(|b| {
            if b[1].is_finite() {
                format!("{}–{} s", b[0], b[1])
            } else {
                format!("{} s–end", b[0])
            }
        })
        .collect()
}

/// Whether stage 3 keyed by heating history ([`FittedUnit::by_history`]) replaces the paper's
/// lookup by rise on one axis of the loop's model: where on the training activations (field-like
/// use at the calibration set points; never the held-out ones) it leaves significantly less drift
/// than the paper's lookup (paired by activation, one-sided, 5 %) — the guard's rule for a term,
/// applied to a lookup. The diagnosis then looks behind the chosen model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stage3Choice {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Whether the fit found crossing curves on this axis ([`FittedUnit::crossings`]): the rise
    /// then names another history on every activation.
    pub curves_cross: bool,
    /// Training activations compared.
    pub training_activations: usize,
    /// Their mean drift with the paper's lookup, °/s.
    pub training_drift_by_rise_dps: f64,
    /// Their mean drift keyed by history, °/s.
    pub training_drift_by_history_dps: f64,
    /// One-sided p-value of "keyed by history leaves less drift" (paired by activation).
    pub p_value: f64,
    /// The choice.
    pub keyed_by_history: bool,
}

/// Chooses stage 3's lookup per axis on the `training` activations, each started after what
/// firmware kept before it (`kept`, in `training`'s order).
fn choose_stage3(
    fitted: &FittedUnit,
    training: &[&Segment],
    kept: &[[Previous; 3]],
    settings: &FitSettings,
) -> [Stage3Choice; 3] {
    let per_activation: Vec<([f64; 3], [f64; 3])> = training
        .par_iter()
        .zip(kept)
        .map(|(segment, previous)| {
            let on = switch_on_raw(segment, settings);
            let window = settings.lowpass_window(segment.sample_rate_hz);
            let (rise, _) = metric(
                &correct_segment_after(&fitted.modified, segment, on, None).0,
                window,
            );
            let (history, _) = metric(
                &correct_segment_after(&fitted.by_history, segment, on, Some(previous)).0,
                window,
            );
            (rise, history)
        })
        .collect();
    std::array::from_fn(|a| {
        let choice = paired_choice(&per_activation, a);
        Stage3Choice {
            axis: ["X", "Y", "Z"][a],
            curves_cross: fitted.crossings.iter().any(|c| c.axis == a),
            training_activations: per_activation.len(),
            training_drift_by_rise_dps: choice.current,
            training_drift_by_history_dps: choice.alternative,
            p_value: choice.p_value,
            keyed_by_history: choice.chosen,
        }
    })
}

/// Splits `segments` (one unit's) by role, chooses stage 3's lookup per axis on the training
/// activations ([`Stage3Choice`]; `clock`: the firmware also knows when the unit cooled fully,
/// [`drift_evaluate::evaluate::kept_before`]), diagnoses the chosen model on the training activations (or,
/// without any, on every activation the fit did not see), and with `extend` fits the guarded
/// extended model. The protocol activations at `selection_set_points` (set points the fit did not
/// use) are diagnosed beside the training ones and not measured on ([`Roles::select`]).
pub fn close<'a>(
    fitted: &FittedUnit,
    segments: impl IntoIterator<Item = &'a Segment>,
    calibration_set_points: &[f64],
    selection_set_points: &[f64],
    settings: &FitSettings,
    extend_model: bool,
    clock: bool,
) -> Result<Closed<'a>, FitError> {
    let mut roles = Roles::split(segments, calibration_set_points);
    roles.hold_out_outside_range(fitted, settings);
    roles.select(selection_set_points);
    // The unit's whole life in order, as its firmware would have lived it: every activation
    // passes what it kept on to the next.
    let life: Vec<&Segment> = roles
        .calibration
        .iter()
        .chain(&roles.training)
        .chain(&roles.selection)
        .chain(&roles.held_out)
        .copied()
        .collect();
    let kept = kept_before(&life, settings, &fitted.by_history.settings, clock);
    close_roles(fitted, roles, &life, &kept, settings, extend_model)
}

/// [`close`] with the judging on a separate source: the roles, stage 3's and the initial bias's
/// choices, the diagnosis and the extended model come from `calibration_source` (one unit's
/// activations of the data the tables were fitted on), and every activation of `evaluation` (the
/// same unit's, recorded apart) is held out — none of them reaches a choice or a fit. The
/// calibration source's own activations outside its roles are not judged on
/// ([`Roles::not_judged`]; the diagnosis ranks on them when there are no training or selection
/// activations, [`Roles::diagnosed`]). Each source is its own life of the unit: what firmware kept is followed
/// within each, never from one into the other. Activations are known by their switch-on time
/// ([`Keying`]), so the two sources' must differ (put the evaluation data after the calibration
/// data on the clock); a shared one is an error.
#[allow(clippy::too_many_arguments)]
pub fn close_separate<'a>(
    fitted: &FittedUnit,
    calibration_source: impl IntoIterator<Item = &'a Segment>,
    evaluation: impl IntoIterator<Item = &'a Segment>,
    calibration_set_points: &[f64],
    selection_set_points: &[f64],
    settings: &FitSettings,
    extend_model: bool,
    clock: bool,
) -> Result<Closed<'a>, FitError> {
    let source: Vec<&Segment> = calibration_source.into_iter().collect();
    let evaluation: Vec<&Segment> = evaluation.into_iter().collect();
    let on: std::collections::HashSet<u64> = source.iter().map(|s| s.power_on_ns).collect();
    if let Some(shared) = evaluation.iter().find(|s| on.contains(&s.power_on_ns)) {
        return Err(FitError::Insufficient {
            unit: fitted.unit_id.clone(),
            what: format!(
                "an evaluation activation (series {} activation {}) switches on at {} ns, as one of the calibration data's: move the evaluation data after the calibration data on the clock",
                shared.labels.series, shared.labels.activation, shared.power_on_ns
            ),
        });
    }
    let mut roles = Roles::split(source.iter().copied(), calibration_set_points);
    roles.hold_out_outside_range(fitted, settings);
    roles.select(selection_set_points);
    roles.not_judged = std::mem::replace(&mut roles.held_out, evaluation);
    let life: Vec<&Segment> = source.iter().chain(&roles.held_out).copied().collect();
    let core = &fitted.by_history.settings;
    let mut kept = kept_before(&source, settings, core, clock);
    kept.extend(kept_before(&roles.held_out, settings, core, clock));
    close_roles(fitted, roles, &life, &kept, settings, extend_model)
}

/// The loop from its roles on: `kept[i]` is what firmware kept before `life[i]`, the unit's
/// activations (every one of `roles`' among them).
fn close_roles<'a>(
    fitted: &FittedUnit,
    roles: Roles<'a>,
    life: &[&'a Segment],
    kept: &[[Previous; 3]],
    settings: &FitSettings,
    extend_model: bool,
) -> Result<Closed<'a>, FitError> {
    let kept_of: std::collections::HashMap<u64, [Previous; 3]> = life
        .iter()
        .zip(kept)
        .map(|(s, k)| (s.power_on_ns, *k))
        .collect();
    let kept_training: Vec<[Previous; 3]> = roles
        .training
        .iter()
        .map(|s| {
            kept_of
                .get(&s.power_on_ns)
                .copied()
                .unwrap_or(Previous::NOTHING)
        })
        .collect();
    let kept_training = kept_training.as_slice();
    let stage3 = choose_stage3(fitted, &roles.training, kept_training, settings);
    let keying = Keying::new(
        std::array::from_fn(|a| stage3[a].keyed_by_history),
        life,
        kept,
    );
    let warm_start = warm_start::choose(fitted, &keying, &roles.training, settings);
    let keying = keying.with_warm_start(std::array::from_fn(|a| warm_start[a].chosen));
    // Where a rate filter starts at switch-on, measured once on the calibration: the diagnosis
    // starts its rate candidates there and the extended model its rate term.
    let switch_on_rate = fit_switch_on_rate(
        &roles.calibration,
        &keying,
        &fitted.modified.settings,
        settings,
    );
    let diagnosed = |keying: &Keying| -> Result<Vec<ActivationSeries>, FitError> {
        let diagnoser = Diagnoser::new(
            fitted,
            &roles.calibration,
            settings,
            keying.clone(),
            switch_on_rate.clone().map(|fit| fit.rate),
        )?;
        Ok(roles
            .diagnosed()
            .iter()
            .map(|s| diagnoser.series(s))
            .collect())
    };
    let series = diagnosed(&keying)?;
    let axes = diagnose(&series);
    let paper_axes = if keying.any() {
        diagnose(&diagnosed(
            &keying
                .with_by_history([false; 3])
                .with_warm_start([false; 3]),
        )?)
    } else {
        axes.clone()
    };
    let proposed = TermPlan::choose(&axes);
    let extended = if extend_model && !proposed.terms.is_empty() && !roles.training.is_empty() {
        Some(extend(
            fitted,
            &keying,
            &proposed,
            &switch_on_rate,
            &roles.calibration,
            &roles.training,
            settings,
        )?)
    } else {
        None
    };
    Ok(Closed {
        roles,
        stage3,
        warm_start,
        keying,
        series,
        axes,
        paper_axes,
        proposed,
        switch_on_rate,
        extended,
    })
}

impl Closed<'_> {
    /// The terms the guard admitted (empty without an extended model).
    pub fn admitted(&self) -> TermPlan {
        self.extended
            .as_ref()
            .map_or_else(TermPlan::default, |e| e.plan.clone())
    }

    /// The loop's model of `fitted` (the unit it was closed with): stage 3 keyed per axis as
    /// chosen, with the admitted terms (the extended model's tables when one was fitted).
    pub fn model(&self, fitted: &FittedUnit) -> Box<drift_core::ModifiedTables> {
        self.extended.as_ref().map_or_else(
            || self.keying.tables(&fitted.modified, &fitted.by_history),
            |e| Box::new(e.tables.clone()),
        )
    }

    /// The loop's output on `segment` (one of the unit's activations): [`Closed::model`] with the
    /// admitted terms (`plan`), started after what firmware kept before it.
    fn corrected(
        &self,
        model: &drift_core::ModifiedTables,
        plan: &TermPlan,
        segment: &Segment,
        on: [f32; 3],
    ) -> [Vec<f32>; 3] {
        correct_with_terms(model, plan, segment, on, self.keying.previous(segment))
    }

    /// Where within each held-out activation the loop's residual sits, in
    /// [`PROFILE_EDGES_S`] bins since switch-on: what separates a transient after switch-on
    /// from an offset or a ramp.
    pub fn profiles(&self, fitted: &FittedUnit, settings: &FitSettings) -> Vec<Profile> {
        let plan = self.admitted();
        let model = self.model(fitted);
        self.roles
            .held_out
            .par_iter()
            .map(|segment| {
                let on = switch_on_raw(segment, settings);
                let after = self.corrected(&model, &plan, segment, on);
                Profile {
                    set_point_celsius: segment.labels.nominal_set_point_celsius(),
                    series_kind: segment.labels.series_kind.as_str(),
                    off_before_s: segment.labels.off_before_s,
                    after_dps: profile(
                        &after,
                        settings.lowpass_window(segment.sample_rate_hz),
                        f64::from(segment.sample_rate_hz),
                        &PROFILE_EDGES_S,
                    ),
                }
            })
            .collect()
    }

    /// The error before (the paper's model `fitted`) and after (the loop's model,
    /// [`Closed::model`]: the paper's when nothing was chosen or admitted) on every held-out
    /// activation.
    ///
    /// The history-keyed model (every axis) runs through the unit's whole life in order, as its
    /// firmware would have lived it ([`Closed::keying`]).
    pub fn before_after(&self, fitted: &FittedUnit, settings: &FitSettings) -> Vec<BeforeAfter> {
        let plan = self.admitted();
        let every_axis = self.keying.with_by_history([true; 3]);
        let model = self.model(fitted);
        self.roles
            .held_out
            .iter()
            .map(|segment| {
                let on = switch_on_raw(segment, settings);
                let window = settings.lowpass_window(segment.sample_rate_hz);
                let (history_drift, history_rms) = metric(
                    &every_axis.correct(&fitted.by_history, segment, on).0,
                    window,
                );
                let before = correct_with_terms(&fitted.modified, &plan, segment, on, None);
                let after = self.corrected(&model, &plan, segment, on);
                let (drift_before, rms_before) = metric(&before, window);
                let (drift_after, rms_after) = metric(&after, window);
                let mean = |rates: &[f32]| {
                    rates.iter().map(|&r| f64::from(r)).sum::<f64>() / rates.len().max(1) as f64
                };
                let kept = self.keying.kept(segment);
                let residual_heat_celsius = std::array::from_fn(|a| {
                    let celsius = fitted.modified.settings.celsius(on[a]);
                    f64::from(SwitchOn::estimate(celsius, Some(kept[a])).residual_heat_celsius)
                });
                BeforeAfter {
                    set_point_celsius: segment.labels.nominal_set_point_celsius(),
                    series_kind: segment.labels.series_kind.as_str(),
                    drift_dps: std::array::from_fn(|a| (drift_before[a], drift_after[a])),
                    rms_dps: std::array::from_fn(|a| (rms_before[a], rms_after[a])),
                    by_history_drift_dps: history_drift,
                    by_history_rms_dps: history_rms,
                    mean_dps: std::array::from_fn(|a| (mean(&before[a]), mean(&after[a]))),
                    residual_heat_celsius,
                    off_before_s: segment.labels.off_before_s,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile(series_kind: &'static str, off_before_s: Option<f64>, value: f64) -> Profile {
        let bins = PROFILE_EDGES_S.len() - 1;
        let mut after = vec![value; bins];
        // The activation ends before the last bin.
        after[bins - 1] = f64::NAN;
        Profile {
            set_point_celsius: 33.0,
            series_kind,
            off_before_s,
            after_dps: [after.clone(), after.clone(), after],
        }
    }

    /// Activations fall in their off-time's group, and a group's mean skips the bins an activation
    /// never reached; groups without activations are left out, in a fixed order.
    #[test]
    fn profiles_average_by_protocol_and_off_time() {
        let all = [
            profile("field", Some(1200.0), 1.0),
            profile("field", Some(45.0), 2.0),
            profile("field", Some(60.0), 4.0),
            profile("protocol", Some(60.0), 8.0),
            profile("field", None, 16.0),
        ];
        let groups: Vec<&str> = all.iter().map(Profile::group).collect();
        assert_eq!(
            groups,
            [
                PROFILE_GROUPS[3],
                PROFILE_GROUPS[1],
                PROFILE_GROUPS[1],
                PROFILE_GROUPS[0],
                PROFILE_GROUPS[4]
            ]
        );
        let refs: Vec<&Profile> = all.iter().collect();
        let means = mean_profiles(&refs);
        let summary: Vec<(&str, usize, f64)> = means
            .iter()
            .map(|(group, n, axes)| (*group, *n, axes[2][0]))
            .collect();
        assert_eq!(
            summary,
            [
                (PROFILE_GROUPS[0], 1, 8.0),
                (PROFILE_GROUPS[1], 2, 3.0),
                (PROFILE_GROUPS[3], 1, 1.0),
                (PROFILE_GROUPS[4], 1, 16.0)
            ]
        );
        assert!(means
            .iter()
            .all(|(_, _, axes)| axes[0].last().unwrap().is_nan()));
        assert_eq!(profile_bin_labels().last().unwrap(), "90 s–end");
    }
}
