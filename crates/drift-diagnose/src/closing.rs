//! Closing the loop for one unit, in the data's one direction: activations by role → stage 3's
//! lookup chosen per axis (by rise, the paper's, or by heating history) → the initial bias chosen
//! per axis (the paper's, or with the warm starts') → the diagnosis of that model's residual →
//! proposed terms → the guarded extended model → the error before and after on the held-out
//! activations. The command line (`gyrodrift diagnose [--extend]`), the Python module and the
//! closed-loop experiment all run this.

use std::collections::HashMap;

use drift_core::{Previous, SwitchOn};
use drift_recording::{Progress, Segment};
use rayon::prelude::*;
use serde::Serialize;

use crate::diagnose::{diagnose, ActivationSeries, AxisDiagnosis, Diagnoser, RANKING};
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
    /// With the analyst's diagnosis data cross-fitted: which half of its series this loop ranked
    /// and fitted on (0 or 1; the other half is among the held-out activations).
    pub half: Option<usize>,
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

/// What the analyst asks of one unit's loop.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoopOptions {
    /// The chamber set points whose protocol activations the paper's tables are fitted on, °C.
    pub calibration_set_points: Vec<f64>,
    /// Set points (not the calibration's) whose protocol activations the diagnosis also ranks on,
    /// none of them measured on afterwards ([`Roles::select`]).
    pub select_on: Vec<f64>,
    /// Set points whose series, field and protocol, are the analyst's diagnosis data, cross-fitted
    /// by series ([`Roles::diagnose_on`]).
    pub diagnose_on: Vec<f64>,
    /// Recorded channels that describe the bench, not the unit (the chamber's air and set point by
    /// default, [`crate::candidates::DEFAULT_BENCH_CHANNELS`]): never ranked, never a term.
    pub bench_channels: Vec<String>,
    /// Build, guard and measure the extended model.
    pub extend: bool,
    /// The firmware knows when the unit cooled fully ([`drift_evaluate::evaluate::kept_before`]).
    pub clock: bool,
    /// Which half of the diagnosis series this loop ranks and fits on (0 or 1); the other half is
    /// held out and judges.
    pub half: usize,
}

impl LoopOptions {
    /// The loop over the calibration at `calibration_set_points`, the default bench channels, the
    /// firmware's clock known.
    pub fn new(calibration_set_points: &[f64]) -> Self {
        Self {
            calibration_set_points: calibration_set_points.to_vec(),
            bench_channels: crate::candidates::DEFAULT_BENCH_CHANNELS
                .iter()
                .map(|c| (*c).to_owned())
                .collect(),
            clock: true,
            ..Self::default()
        }
    }

    /// Whether the analyst named diagnosis data (set points or another source), so that the loop
    /// runs twice, once per half.
    pub fn cross_fitted(&self, diagnosis_data: &[&Segment]) -> bool {
        !self.diagnose_on.is_empty() || !diagnosis_data.is_empty()
    }
}

/// The roles of one source: split, the training outside the ambient range held out, the
/// selection and the diagnosis series of `half` moved in (`diagnosis_data`: activations of
/// another source that are the analyst's diagnosis data whatever their set point).
fn roles_of<'a>(
    fitted: &FittedUnit,
    source: &[&'a Segment],
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    half: usize,
) -> Roles<'a> {
    let mut roles = Roles::split(source.iter().copied(), &options.calibration_set_points);
    roles.hold_out_outside_range(fitted, settings);
    roles.select(&options.select_on);
    if options.cross_fitted(diagnosis_data) {
        roles.held_out.extend(diagnosis_data);
        let named = |s: &Segment| {
            diagnosis_data.iter().any(|d| std::ptr::eq(*d, s))
                || drift_evaluate::pipeline::is_one_of(
                    s.labels.nominal_set_point_celsius(),
                    &options.diagnose_on,
                )
        };
        roles.diagnose_on(named, half);
    }
    roles
}

/// Splits `segments` (one unit's) by role, chooses stage 3's lookup per axis on the training
/// activations ([`Stage3Choice`]), diagnoses the chosen model on the training, selection and
/// diagnosis activations (or, without any, on every activation the fit did not see), and with
/// `options.extend` fits the guarded extended model. `diagnosis_data` (another source's
/// activations of the same unit, placed after `segments` on the clock) joins the analyst's
/// diagnosis data.
///
/// With diagnosis data (`options.diagnose_on` or `diagnosis_data`) this is the loop of the half
/// `options.half`; [`close_both`] runs both halves at the cost of little more than one.
///
/// `progress` is told the axes ranked ([`RANKING`], over every ranking the loop makes) and asked
/// between the ranking's shuffles whether to go on; [`FitError::Interrupted`] when it asks to stop.
pub fn close<'a>(
    fitted: &FittedUnit,
    segments: impl IntoIterator<Item = &'a Segment>,
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    progress: &dyn Progress,
) -> Result<Closed<'a>, FitError> {
    let source: Vec<&Segment> = segments.into_iter().collect();
    first_of(
        fitted,
        close_each(
            fitted,
            &source,
            diagnosis_data,
            options,
            settings,
            &[options.half],
            progress,
        )?,
    )
}

/// [`close`] for every half of the analyst's diagnosis data (two when there are any, cross-fitted:
/// each half ranked, fitted and guarded on, and judged by the other; else the one loop).
pub fn close_both<'a>(
    fitted: &FittedUnit,
    segments: impl IntoIterator<Item = &'a Segment>,
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    progress: &dyn Progress,
) -> Result<Vec<Closed<'a>>, FitError> {
    let source: Vec<&Segment> = segments.into_iter().collect();
    close_each(
        fitted,
        &source,
        diagnosis_data,
        options,
        settings,
        halves(options, diagnosis_data),
        progress,
    )
}

/// The halves a cross-fitted loop runs: both with diagnosis data, else the one asked for.
fn halves<'h>(options: &'h LoopOptions, diagnosis_data: &[&Segment]) -> &'h [usize] {
    if options.cross_fitted(diagnosis_data) {
        &[0, 1]
    } else {
        std::slice::from_ref(&options.half)
    }
}

fn first_of<'a>(fitted: &FittedUnit, closed: Vec<Closed<'a>>) -> Result<Closed<'a>, FitError> {
    closed
        .into_iter()
        .next()
        .ok_or_else(|| FitError::Insufficient {
            unit: fitted.unit_id.clone(),
            what: "no loop was run".into(),
        })
}

fn close_each<'a>(
    fitted: &FittedUnit,
    source: &[&'a Segment],
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    halves: &[usize],
    progress: &dyn Progress,
) -> Result<Vec<Closed<'a>>, FitError> {
    let roles = halves
        .iter()
        .map(|&half| roles_of(fitted, source, diagnosis_data, options, settings, half))
        .collect();
    // The unit's whole life in order, as its firmware would have lived it: every activation
    // passes what it kept on to the next.
    let mut life: Vec<&Segment> = source.iter().chain(diagnosis_data).copied().collect();
    life.sort_by_key(|s| s.power_on_ns);
    let kept = kept_before(&life, settings, &fitted.by_history.settings, options.clock);
    close_halves(fitted, roles, &life, &kept, settings, options, progress)
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
pub fn close_separate<'a>(
    fitted: &FittedUnit,
    calibration_source: impl IntoIterator<Item = &'a Segment>,
    evaluation: impl IntoIterator<Item = &'a Segment>,
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    progress: &dyn Progress,
) -> Result<Closed<'a>, FitError> {
    let closed = close_separate_each(
        fitted,
        calibration_source,
        evaluation,
        diagnosis_data,
        options,
        settings,
        &[options.half],
        progress,
    )?;
    first_of(fitted, closed)
}

/// [`close_separate`] for every half of the analyst's diagnosis data ([`close_both`]).
pub fn close_separate_both<'a>(
    fitted: &FittedUnit,
    calibration_source: impl IntoIterator<Item = &'a Segment>,
    evaluation: impl IntoIterator<Item = &'a Segment>,
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    progress: &dyn Progress,
) -> Result<Vec<Closed<'a>>, FitError> {
    close_separate_each(
        fitted,
        calibration_source,
        evaluation,
        diagnosis_data,
        options,
        settings,
        halves(options, diagnosis_data),
        progress,
    )
}

#[allow(clippy::too_many_arguments)]
fn close_separate_each<'a>(
    fitted: &FittedUnit,
    calibration_source: impl IntoIterator<Item = &'a Segment>,
    evaluation: impl IntoIterator<Item = &'a Segment>,
    diagnosis_data: &[&'a Segment],
    options: &LoopOptions,
    settings: &FitSettings,
    halves: &[usize],
    progress: &dyn Progress,
) -> Result<Vec<Closed<'a>>, FitError> {
    let source: Vec<&Segment> = calibration_source.into_iter().collect();
    let evaluation: Vec<&Segment> = evaluation.into_iter().collect();
    let on: std::collections::HashSet<u64> = source
        .iter()
        .chain(diagnosis_data)
        .map(|s| s.power_on_ns)
        .collect();
    if let Some(shared) = evaluation.iter().find(|s| on.contains(&s.power_on_ns)) {
        return Err(FitError::Insufficient {
            unit: fitted.unit_id.clone(),
            what: format!(
                "an evaluation activation (series {} activation {}) switches on at {} ns, as one of the calibration data's: move the evaluation data after the calibration data on the clock",
                shared.labels.series, shared.labels.activation, shared.power_on_ns
            ),
        });
    }
    // Judged on the evaluation data alone: what the calibration source holds outside its roles
    // (the other half of the diagnosis series among it) is not judged on.
    let roles: Vec<Roles> = halves
        .iter()
        .map(|&half| {
            let mut roles = roles_of(fitted, &source, diagnosis_data, options, settings, half);
            roles.not_judged = std::mem::replace(&mut roles.held_out, evaluation.clone());
            roles
        })
        .collect();
    let mut own: Vec<&Segment> = source.iter().chain(diagnosis_data).copied().collect();
    own.sort_by_key(|s| s.power_on_ns);
    let life: Vec<&Segment> = own.iter().chain(&evaluation).copied().collect();
    let core = &fitted.by_history.settings;
    let mut kept = kept_before(&own, settings, core, options.clock);
    kept.extend(kept_before(&evaluation, settings, core, options.clock));
    close_halves(fitted, roles, &life, &kept, settings, options, progress)
}

/// One of a loop's rankings as [`RANKING`] over all of them: `before` axes were ranked by the
/// rankings before it, of `total`.
struct Ranked<'p> {
    outer: &'p dyn Progress,
    before: u64,
    total: u64,
}

impl Progress for Ranked<'_> {
    fn report(&self, _: &str, done: u64, _: u64) -> std::ops::ControlFlow<()> {
        self.outer.report(RANKING, self.before + done, self.total)
    }
}

/// The loop from its roles on, for each of `halves` (one, or two when the analyst's diagnosis
/// data are cross-fitted): `kept[i]` is what firmware kept before `life[i]`, the unit's activations
/// (every one of the roles' among them). The halves share their calibration and training roles, so
/// stage 3's and the initial bias's choices, the rate filters' start and every candidate's
/// absorber are made once, and each diagnosed activation is put on the grid once.
fn close_halves<'a>(
    fitted: &FittedUnit,
    halves: Vec<Roles<'a>>,
    life: &[&'a Segment],
    kept: &[[Previous; 3]],
    settings: &FitSettings,
    options: &LoopOptions,
    progress: &dyn Progress,
) -> Result<Vec<Closed<'a>>, FitError> {
    let Some(first) = halves.first() else {
        return Ok(Vec::new());
    };
    let kept_of: std::collections::HashMap<u64, [Previous; 3]> = life
        .iter()
        .zip(kept)
        .map(|(s, k)| (s.power_on_ns, *k))
        .collect();
    let kept_training: Vec<[Previous; 3]> = first
        .training
        .iter()
        .map(|s| {
            kept_of
                .get(&s.power_on_ns)
                .copied()
                .unwrap_or(Previous::NOTHING)
        })
        .collect();
    let stage3 = choose_stage3(fitted, &first.training, &kept_training, settings);
    let keying = Keying::new(
        std::array::from_fn(|a| stage3[a].keyed_by_history),
        life,
        kept,
    );
    let warm_start = warm_start::choose(fitted, &keying, &first.training, settings);
    let keying = keying.with_warm_start(std::array::from_fn(|a| warm_start[a].chosen));
    // Where a rate filter starts at switch-on, measured once on the calibration: the diagnosis
    // starts its rate candidates there and the extended model its rate term.
    let switch_on_rate = fit_switch_on_rate(
        &first.calibration,
        &keying,
        &fitted.modified.settings,
        settings,
    );
    // Every activation any half diagnoses, on the grid once per model diagnosed.
    let mut union: Vec<&Segment> = halves.iter().flat_map(Roles::diagnosed).collect();
    union.sort_by_key(|s| s.power_on_ns);
    union.dedup_by_key(|s| s.power_on_ns);
    let on_grid = |keying: &Keying| -> Result<HashMap<u64, ActivationSeries>, FitError> {
        let diagnoser = Diagnoser::new(
            fitted,
            &first.calibration,
            settings,
            keying.clone(),
            switch_on_rate.clone().map(|fit| fit.rate),
            &options.bench_channels,
        )?;
        Ok(union
            .iter()
            .map(|s| (s.power_on_ns, diagnoser.series(s)))
            .collect())
    };
    let loop_grid = on_grid(&keying)?;
    let paper_grid = if keying.any() {
        Some(on_grid(
            &keying
                .with_by_history([false; 3])
                .with_warm_start([false; 3]),
        )?)
    } else {
        None
    };
    let pick =
        |grid: &HashMap<u64, ActivationSeries>, roles: &Roles<'a>| -> Vec<ActivationSeries> {
            roles
                .diagnosed()
                .iter()
                .filter_map(|s| grid.get(&s.power_on_ns).cloned())
                .collect()
        };
    let cross_fitted = halves.len() > 1;
    let per_half = if paper_grid.is_some() { 2 } else { 1 };
    let rankings = 3 * per_half * halves.len() as u64;
    let ranked = |k: u64| Ranked {
        outer: progress,
        before: 3 * k,
        total: rankings,
    };
    halves
        .into_iter()
        .enumerate()
        .map(|(half, roles)| {
            let series = pick(&loop_grid, &roles);
            let first_ranking = per_half * half as u64;
            let axes = diagnose(&series, &ranked(first_ranking))?;
            let paper_axes = match &paper_grid {
                Some(grid) => diagnose(&pick(grid, &roles), &ranked(first_ranking + 1))?,
                None => axes.clone(),
            };
            let proposed = TermPlan::choose(&axes);
            let fitting = roles.fitting();
            let extended = if options.extend && !proposed.terms.is_empty() && !fitting.is_empty() {
                Some(extend(
                    fitted,
                    &keying,
                    &proposed,
                    &switch_on_rate,
                    &roles.calibration,
                    &fitting,
                    settings,
                )?)
            } else {
                None
            };
            let half = if cross_fitted {
                Some(half)
            } else {
                (!roles.diagnosis.is_empty()).then_some(options.half)
            };
            Ok(Closed {
                roles,
                stage3: stage3.clone(),
                warm_start: warm_start.clone(),
                keying: keying.clone(),
                series,
                axes,
                paper_axes,
                proposed,
                switch_on_rate: switch_on_rate.clone(),
                extended,
                half,
            })
        })
        .collect()
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
