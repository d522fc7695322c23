//! The closed loop's last step: the diagnosis's significant winners become the extended model's
//! extra terms ([`drift_core::Extension`]); their coefficients are fitted on training activations
//! the tables never saw, and the tables are refitted on the calibration activations with the terms'
//! contribution taken out, alternating until both settle.
//!
//! The term values always come from drift-core's own [`ExtensionState::values`] on the same
//! inputs the firmware sees, so the fitted coefficients mean in firmware what they meant here.
//!
//! Why training activations apart from the calibration ones: the paper's table is a lookup over
//! (time since switch-on, ambient, heating history under the protocol), so on protocol activations
//! it has already absorbed any effect that is a fixed function of those. An effect's coefficient is
//! only identifiable where its driver varies independently of the table's inputs: activations with
//! other off-times, supply voltages, orientations — field-like use recorded at the calibration
//! ambients.

use drift_core::{
    Corrector, Extension, ExtensionState, ExtraTerm, Model, ModifiedTables, Previous, Settings,
    SwitchOnRate, Term, TermInputs, AUX_INPUTS, MAX_TERMS,
};
use drift_recording::Segment;
use rayon::prelude::*;
use serde::Serialize;

use crate::absorb::Absorber;
use crate::candidates::{Kind, SET_POINT_CHANNEL};
use crate::diagnose::{AxisDiagnosis, WITHIN_ACTIVATIONS};
use crate::keying::Keying;
use crate::switch_on_rate::{switch_ons, without_heating, SwitchOnRateFit};
use drift_evaluate::evaluate::{metric, sample_at, switch_on_raw};
use drift_fit::analyse::analyse;
use drift_fit::error::FitError;
use drift_fit::fit::{fit_unit_at, reference_indices, FittedUnit};
use drift_fit::lowpass::centred_moving_average;
use drift_fit::settings::FitSettings;

/// Time constant of an auxiliary term's low-pass, ms: the diagnosis scores a channel through the
/// fit's 1-s window, and a recorded channel's sample noise (2 mV on a 5 V supply at 100 Hz) passed
/// straight into the correction made the drift metric worse (supply voltage on Y at 5×). A first-order low-pass of time constant τ has the noise bandwidth 1/(4τ): at 1 s half
/// the 1-s window's (1/(2 s)); it lags a step of its input by τ, and the offsets it is for change
/// at switch-on (supply, orientation), not within a second.
pub const AUX_TIME_CONSTANT_MS: u32 = 1000;

const AXIS_NAMES: [&str; 3] = ["X", "Y", "Z"];

/// One extra term chosen from the diagnosis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChosenTerm {
    /// What it computes, named after the diagnosis candidate it came from.
    pub candidate: String,
    /// The term's kind, as drift-core computes it.
    #[serde(skip)]
    pub term: Term,
    /// The axes whose diagnosis found this term's candidate significant (its siblings of a vector
    /// channel and the other axes were not): there the term is admitted unless it makes the
    /// held-out data worse; elsewhere it must show a held-out gain of its own.
    pub found_on: [bool; 3],
    /// Fitted and judged as a shape within activations (by the drift), not as offsets between
    /// them (by the squared residual): every kind but an auxiliary input, and an auxiliary input
    /// whose diagnosis found it within activations. A channel that moves within an activation
    /// (humidity through a housing's lag, or the simulator's truth of an effect × rise) fitted on
    /// the offsets between activations took its coefficient from the switch-on offsets' scatter:
    /// given a world's true effect as a channel, the loop refused it for raising the held-out
    /// drift by 0.0045 °/s.
    pub shape: bool,
}

/// The extra terms and which recorded auxiliary channel feeds each auxiliary input.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TermPlan {
    /// The terms, in table order.
    pub terms: Vec<ChosenTerm>,
    /// `aux_inputs[i]` is the recording's auxiliary channel the firmware passes as input `i`.
    pub aux_inputs: Vec<String>,
    /// Whether the rate terms are the element's rate (the filter starts at the cooling alone) or
    /// the sensor's (heating included); `None` without a rate term.
    pub element_rate: Option<bool>,
    /// Per axis, where the rate filter starts at switch-on ([`extend`] measures it on the
    /// calibration; at rest until then).
    #[serde(skip)]
    pub switch_on_rate: [SwitchOnRate; 3],
}

impl TermPlan {
    /// The term a diagnosis candidate stands for, if the firmware can compute it per sample.
    /// Time since switch-on, switch-on temperature and the off-time estimate are the table's own
    /// inputs; campaign time is ageing, which no thermal term should model.
    fn term_for(&mut self, candidate: &str) -> Option<Term> {
        if let Some(time_constant_s) = Kind::rate_time_constant_s(candidate) {
            // The filter the diagnosis scored the rate through, started as it started it.
            let time_constant_ms = time_constant_s.checked_mul(1000)?;
            let element = Kind::is_element_rate(candidate);
            // drift-core keeps one rate filter per axis, so every rate term shares its τ and its
            // start: the best-ranked rate candidate sets them.
            let other_filter = self.terms.iter().any(|t| {
                matches!(t.term, Term::TemperatureRate { time_constant_ms: other } if other != time_constant_ms)
            });
            if other_filter || self.element_rate.is_some_and(|e| e != element) {
                return None;
            }
            self.element_rate = Some(element);
            return Some(Term::TemperatureRate { time_constant_ms });
        }
        if candidate.starts_with("rise² ") {
            return Some(Term::RiseSquared);
        }
        if let Some(axis) = candidate.strip_prefix("rise ") {
            let axis = AXIS_NAMES.iter().position(|a| *a == axis)?;
            return Some(Term::AxisRise {
                axis: u8::try_from(axis).ok()?,
            });
        }
        let named = candidate.strip_prefix("aux:")?;
        // An interaction (`aux:supply_voltage × rise X`, `aux:supply_voltage × temperature X (from
        // 25 °C)`) becomes the channel times the own rise: within an activation the temperature
        // moves only by the rise, and drift-core reads no absolute temperature.
        let (channel, interaction) = match named.split_once(" × ") {
            Some((channel, with))
                if with.starts_with("rise ") || with.starts_with("temperature ") =>
            {
                (channel, true)
            }
            Some(_) => return None,
            None => (named, false),
        };
        // The chamber's set point is the bench's ambient: a unit in the field has no chamber to
        // ask, and the paper's tables already index the ambient (by the switch-on temperature).
        if channel == SET_POINT_CHANNEL {
            return None;
        }
        let input = match self.aux_inputs.iter().position(|c| c == channel) {
            Some(input) => input,
            None if self.aux_inputs.len() < AUX_INPUTS => {
                self.aux_inputs.push(channel.to_owned());
                self.aux_inputs.len() - 1
            }
            None => return None,
        };
        let input = u8::try_from(input).ok()?;
        Some(if interaction {
            Term::AuxTimesRise {
                input,
                time_constant_ms: AUX_TIME_CONSTANT_MS,
            }
        } else {
            Term::Aux {
                input,
                time_constant_ms: AUX_TIME_CONSTANT_MS,
            }
        })
    }

    /// The significant candidates of every axis that map to a term, best ranks first across the
    /// axes, each term once, at most [`MAX_TERMS`]. Nothing is offered that the diagnosis did not
    /// find: a rate term offered on every unit regardless (the element lags its sensor on every
    /// physical unit) was admitted by the guard on drawn worlds where it then raised the held-out
    /// drift on 12 of 13 axes (experiments/README.md, *worlds*), and the shuffle test sees a
    /// shape within activations as well as an offset.
    ///
    /// A component of a vector channel (`accel_x`) brings its siblings (`accel_y`, `accel_z`):
    /// a sensitivity to a vector quantity is a matrix, so every axis's bias may follow every
    /// component, and the guard then decides per axis which ones earn their place.
    pub fn choose(axes: &[AxisDiagnosis]) -> Self {
        let mut plan = Self::default();
        let deepest = axes.iter().map(|a| a.ranking.len()).max().unwrap_or(0);
        let siblings = |name: &str| -> Vec<String> {
            let Some(stem) = ["_x", "_y", "_z"]
                .iter()
                .find_map(|suffix| name.strip_suffix(suffix))
            else {
                return vec![name.to_owned()];
            };
            let present = |n: &String| axes.iter().any(|a| a.ranking.iter().any(|c| &c.name == n));
            std::iter::once(name.to_owned())
                .chain(
                    ["_x", "_y", "_z"]
                        .iter()
                        .map(|suffix| format!("{stem}{suffix}"))
                        .filter(|n| n != name && present(n)),
                )
                .collect()
        };
        'ranks: for rank in 0..deepest {
            for axis in axes {
                let Some(candidate) = axis.ranking.get(rank).filter(|c| c.significant) else {
                    continue;
                };
                for name in siblings(&candidate.name) {
                    if plan.terms.len() == MAX_TERMS {
                        break 'ranks;
                    }
                    // A new auxiliary channel always makes a new term, so the channel list only
                    // grows with the terms.
                    let Some(term) = plan.term_for(&name) else {
                        continue;
                    };
                    let axis_index = AXIS_NAMES.iter().position(|a| *a == axis.axis);
                    let found_here = name == candidate.name;
                    let found_within = found_here && candidate.level == WITHIN_ACTIVATIONS;
                    if let Some(known) = plan.terms.iter_mut().find(|t| t.term == term) {
                        if let (Some(a), true) = (axis_index, found_here) {
                            known.found_on[a] = true;
                        }
                        known.shape |= found_within;
                        continue;
                    }
                    let mut found_on = [false; 3];
                    if let (Some(a), true) = (axis_index, found_here) {
                        found_on[a] = true;
                    }
                    plan.terms.push(ChosenTerm {
                        candidate: describe(term, &name),
                        term,
                        found_on,
                        shape: changes_shape(term) || found_within,
                    });
                }
            }
        }
        plan
    }

    /// The plan with only the terms `keep` (indices, in order) and the auxiliary inputs they read,
    /// renumbered.
    fn keeping(&self, keep: &[usize]) -> Self {
        let mut kept = Self::default();
        // Without a rate term the start is unused: the image carries none.
        if keep
            .iter()
            .filter_map(|&t| self.terms.get(t))
            .any(|t| matches!(t.term, Term::TemperatureRate { .. }))
        {
            kept.element_rate = self.element_rate;
            kept.switch_on_rate = self.switch_on_rate;
        }
        for chosen in keep.iter().filter_map(|&t| self.terms.get(t)) {
            let mut chosen = chosen.clone();
            if let Term::Aux {
                input,
                time_constant_ms,
            }
            | Term::AuxTimesRise {
                input,
                time_constant_ms,
            } = chosen.term
            {
                let Some(channel) = self.aux_inputs.get(usize::from(input)) else {
                    continue;
                };
                let renumbered = match kept.aux_inputs.iter().position(|c| c == channel) {
                    Some(i) => i,
                    None => {
                        kept.aux_inputs.push(channel.clone());
                        kept.aux_inputs.len() - 1
                    }
                };
                let Ok(input) = u8::try_from(renumbered) else {
                    continue;
                };
                chosen.term = match chosen.term {
                    Term::AuxTimesRise { .. } => Term::AuxTimesRise {
                        input,
                        time_constant_ms,
                    },
                    _ => Term::Aux {
                        input,
                        time_constant_ms,
                    },
                };
            }
            kept.terms.push(chosen);
        }
        kept
    }

    /// The auxiliary inputs of sample `i` of `segment`, NaN where the channel is missing.
    fn aux_at(&self, segment: &Segment, i: usize) -> [f32; AUX_INPUTS] {
        let mut aux = [f32::NAN; AUX_INPUTS];
        for (value, name) in aux.iter_mut().zip(&self.aux_inputs) {
            if let Some(channel) = segment.aux.get(name) {
                let at =
                    i * channel.sample_rate_hz as usize / segment.sample_rate_hz.max(1) as usize;
                *value = channel
                    .values
                    .get(at.min(channel.values.len().saturating_sub(1)))
                    .copied()
                    .unwrap_or(f32::NAN);
            }
        }
        aux
    }

    /// The extension with these terms and the given centres and coefficients per term.
    fn extension(&self, centre: &[[f32; 3]], coefficient: &[[f32; 3]]) -> Extension {
        let mut extension = Extension {
            switch_on_rate: self.switch_on_rate,
            ..Extension::NONE
        };
        for (i, chosen) in self.terms.iter().enumerate() {
            let _ = extension.terms.push(ExtraTerm {
                term: chosen.term,
                centre: centre.get(i).copied().unwrap_or([0.0; 3]),
                coefficient: coefficient.get(i).copied().unwrap_or([0.0; 3]),
            });
        }
        extension
    }
}

/// What a term computes, for reports: the own-axis kinds are named by kind (the diagnosis found them
/// on one axis, the term applies its kind on every axis).
fn describe(term: Term, candidate: &str) -> String {
    match term {
        Term::TemperatureRate { time_constant_ms } => format!(
            "{} (own axis, τ {} s)",
            if Kind::is_element_rate(candidate) {
                "element rate"
            } else {
                "temperature rate"
            },
            f64::from(time_constant_ms) / 1000.0
        ),
        Term::RiseSquared => "rise² (own axis)".into(),
        Term::AuxTimesRise { .. } => candidate.split_once(" × ").map_or_else(
            || candidate.to_owned(),
            |(channel, _)| format!("{channel} × rise (own axis)"),
        ),
        _ => candidate.to_owned(),
    }
}

/// Corrects a whole activation with `tables` (extended or not), passing the plan's auxiliary
/// inputs: the firmware's path, sample by sample; started after `previous` (what firmware kept of
/// the activation before) when given, as stage 3 keyed by history needs.
pub fn correct_with_terms<M: Model>(
    tables: &M,
    plan: &TermPlan,
    segment: &Segment,
    switch_on: [f32; 3],
    previous: Option<[Previous; 3]>,
) -> [Vec<f32>; 3] {
    let mut corrected: [Vec<f32>; 3] = Default::default();
    let Ok(mut corrector) = Corrector::new(tables) else {
        return segment.rate_dps.clone();
    };
    let started = match previous {
        Some(mut previous) => corrector.power_on_after(switch_on, &mut previous),
        None => corrector.power_on(switch_on),
    };
    if started.is_err() {
        return segment.rate_dps.clone();
    }
    for i in 0..segment.len() {
        let out = corrector.correct_with_aux(&sample_at(segment, i), &plan.aux_at(segment, i));
        for (axis, values) in corrected.iter_mut().enumerate() {
            values.push(out.corrected_dps[axis]);
        }
    }
    corrected
}

/// Per term, the uncentred values of every sample on every axis, as the corrector computes them
/// (the last good temperature is held through faults; the rate filter started from what firmware
/// kept before, `previous`, as `power_on_after` starts it).
fn term_values(
    plan: &TermPlan,
    settings: &Settings,
    segment: &Segment,
    switch_on: [f32; 3],
    previous: Option<[Previous; 3]>,
) -> Vec<[Vec<f32>; 3]> {
    let shape = plan.extension(&[], &[]);
    let starts = switch_ons(settings, switch_on, previous);
    let mut state = ExtensionState::power_on_after(&shape, &starts);
    let mut held = switch_on;
    // The corrector's conversion: times the reciprocal, the same bits.
    let celsius_per_raw = 1.0 / settings.raw_per_celsius;
    let mut values: Vec<[Vec<f32>; 3]> = (0..plan.terms.len())
        .map(|_| std::array::from_fn(|_| Vec::with_capacity(segment.len())))
        .collect();
    for i in 0..segment.len() {
        let sample = sample_at(segment, i);
        for (held, raw) in held.iter_mut().zip(sample.temperature_raw) {
            if raw.is_finite() {
                *held = raw;
            }
        }
        let inputs = TermInputs {
            since_power_on_ms: sample.since_power_on_ms,
            rise_celsius: [0, 1, 2].map(|a| (held[a] - switch_on[a]) * celsius_per_raw),
            aux: plan.aux_at(segment, i),
        };
        let row = state.values(&shape, &inputs);
        for (term, per_axis) in values.iter_mut().enumerate() {
            for (axis, column) in per_axis.iter_mut().enumerate() {
                column.push(row[axis][term]);
            }
        }
    }
    values
}

/// Family-wise significance level of the guard over every (term, axis) it tests.
const ADMIT_ALPHA: f64 = 0.05;
/// Folds of the guard's cross-validation by series.
const FOLDS: usize = 5;

/// What the guard decided for one term on one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Admission {
    /// The term's diagnosis candidate.
    pub candidate: String,
    /// Axis name.
    pub axis: &'static str,
    /// Mean held-out reduction of the squared residual per activation (°/s)², cross-validated by
    /// activation, against the terms admitted before it.
    pub improvement: f64,
    /// One-sided p-value of that reduction.
    pub p_value: f64,
    /// Mean held-out reduction of the paper's drift metric per activation, °/s (the term is
    /// refused when it is significantly negative).
    pub drift_gain_dps: f64,
    /// One-sided p-value of that reduction: the test a term that changes the shape within
    /// activations (rate, rise², another axis's rise) is admitted on; an auxiliary input is
    /// admitted on `p_value`.
    pub drift_p_value: f64,
    /// Whether the term was admitted on this axis (coefficient fitted) or left at zero.
    pub admitted: bool,
    /// Why, in words: every decision, and every refusal above all, says what it rests on.
    pub reason: String,
}

/// One training activation on a 10 Hz grid: the paper model's residual and, per term, what the
/// tables leave of the term's values, per axis.
struct TrainingSeries {
    residual: [Vec<f64>; 3],
    terms: Vec<[Vec<f64>; 3]>,
    /// Per term and axis, the mean of the term's raw values (for the centres).
    raw_sum: Vec<[(f64, usize); 3]>,
}

fn training_series(
    base: &ModifiedTables,
    keying: &Keying,
    plan: &TermPlan,
    absorbers: &[Absorber],
    segment: &Segment,
    settings: &FitSettings,
) -> TrainingSeries {
    let window = settings.lowpass_window(segment.sample_rate_hz);
    let step = (segment.sample_rate_hz as usize / 10).max(1);
    let grid = |v: &[f32]| -> Vec<f64> {
        centred_moving_average(v, window)
            .into_iter()
            .step_by(step)
            .collect()
    };
    let switch_on = switch_on_raw(segment, settings);
    let residual = correct_with_terms(base, plan, segment, switch_on, keying.previous(segment));
    let values = term_values(
        plan,
        base.settings(),
        segment,
        switch_on,
        keying.previous(segment),
    );
    let raw_sum = values
        .iter()
        .map(|per_axis| {
            per_axis.clone().map(|v| {
                v.iter()
                    .filter(|x| x.is_finite())
                    .fold((0.0, 0), |(s, n), &x| (s + f64::from(x), n + 1))
            })
        })
        .collect();
    let terms = values
        .into_iter()
        .zip(absorbers)
        .map(|(v, absorber)| {
            absorber
                .left_over(segment, v, switch_on, keying)
                .map(|l| grid(&l))
        })
        .collect();
    TrainingSeries {
        residual: residual.map(|r| grid(&r)),
        terms,
        raw_sum,
    }
}

/// Least squares over `series` of `axis`'s residual, less `known` (per activation and grid point,
/// what terms already fitted explain), on the `chosen` terms' left-over values. `within`: on each
/// activation's variation about its own mean (an intercept per activation), the shape within
/// activations; otherwise on one intercept for all, offsets between activations included. Returns
/// the coefficients of `chosen`, in order.
fn joint_fit(
    series: &[&TrainingSeries],
    axis: usize,
    chosen: &[usize],
    known: &[Vec<f64>],
    within: bool,
) -> Vec<f64> {
    let mut rows = Vec::new();
    let mut ys = Vec::new();
    let mean = |values: &mut dyn Iterator<Item = f64>| {
        let (sum, n) = values
            .filter(|v| v.is_finite())
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        if within && n > 0 {
            sum / n as f64
        } else {
            0.0
        }
    };
    for (s, known) in series.iter().zip(known) {
        let y = |i: usize| s.residual[axis][i] - known.get(i).copied().unwrap_or(0.0);
        let y_mean = mean(&mut (0..s.residual[axis].len()).map(y));
        let term_means: Vec<f64> = chosen
            .iter()
            .map(|&t| mean(&mut s.terms[t][axis].iter().copied()))
            .collect();
        for i in 0..s.residual[axis].len() {
            // Within activations each one's own mean is its intercept, already taken out.
            let intercept = (!within).then_some(1.0);
            rows.push(
                intercept
                    .into_iter()
                    .chain(
                        chosen
                            .iter()
                            .zip(&term_means)
                            .map(|(&t, m)| s.terms[t][axis][i] - m),
                    )
                    .collect::<Vec<f64>>(),
            );
            ys.push(y(i) - y_mean);
        }
    }
    if chosen.is_empty() {
        return Vec::new();
    }
    let beta = drift_fit::regression::least_squares(&rows, &ys);
    let first = usize::from(!within);
    (0..chosen.len())
        .map(|k| beta.get(first + k).copied().unwrap_or(0.0))
        .collect()
}

/// The paper's tables refitted on `calibration` with `extension`'s contribution removed, carrying
/// the extension: the model firmware would run.
fn refit(
    base: &FittedUnit,
    keying: &Keying,
    plan: &TermPlan,
    extension: &Extension,
    calibration: &[&Segment],
    settings: &FitSettings,
) -> Result<(FittedUnit, ModifiedTables), FitError> {
    let core_settings = base.modified.settings;
    let refitted = if extension
        .terms
        .iter()
        .all(|t| t.coefficient.iter().all(|c| *c == 0.0))
    {
        base.clone()
    } else {
        let analysed = calibration
            .par_iter()
            .map(|s| {
                analyse(
                    &without_terms(extension, plan, &core_settings, s, keying, settings),
                    settings,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        // At the drift fit's reference times: the tables then take of the terms exactly what
        // their absorbers took, and the coefficients fitted on the left-over values mean here
        // what they meant there.
        fit_unit_at(
            &analysed,
            settings,
            Some(&reference_indices(&base.modified, settings)),
        )?
    };
    let tables = keying
        .tables(&refitted.modified, &refitted.by_history)
        .with_extension(extension.clone())
        .map_err(|source| FitError::Table {
            unit: base.unit_id.clone(),
            model: "extended",
            source,
        })?;
    Ok((refitted, tables))
}

/// Per axis, the mean square of the 1-s low-passed residual `tables` leave on `segment`, and the
/// paper's drift metric of it (max − min).
fn errors(
    tables: &ModifiedTables,
    keying: &Keying,
    plan: &TermPlan,
    segment: &Segment,
    settings: &FitSettings,
) -> [(f64, f64); 3] {
    let on = switch_on_raw(segment, settings);
    let corrected = correct_with_terms(tables, plan, segment, on, keying.previous(segment));
    let (drift, rms) = metric(&corrected, settings.lowpass_window(segment.sample_rate_hz));
    std::array::from_fn(|a| (rms[a] * rms[a], drift[a]))
}

/// Coefficients per term and axis over `series`, against the left-over values of the terms
/// `admitted[axis]` (all other coefficients zero), each kind on what it is for, as the guard
/// judges it: the terms that change the shape within activations by least squares on each
/// activation's variation about its own mean; then the auxiliary inputs, which move offsets
/// between activations, on what the shape terms leave, with one intercept.
///
/// Why not one pooled fit: the offsets between activations dominate the squared residual, and a
/// shape term whose left-over values also differ in mean from one activation to the next took its
/// coefficient from those offsets, which the warm starts' initial bias already answers. Fitted on
/// the shape alone the element's rate cut the held-out drift excess ≥ 2× on 6 of 9 axes instead
/// of 4 (thermal lag at 5×, seeds 2–4).
fn coefficients(
    plan: &TermPlan,
    series: &[&TrainingSeries],
    admitted: &[Vec<usize>; 3],
) -> Vec<[f32; 3]> {
    let mut coefficient = vec![[0.0f32; 3]; plan.terms.len()];
    let shapes = |t: &usize| plan.terms.get(*t).is_some_and(|c| c.shape);
    for (axis, chosen) in admitted.iter().enumerate() {
        let (shape, offset): (Vec<usize>, Vec<usize>) = chosen.iter().copied().partition(shapes);
        let none: Vec<Vec<f64>> = vec![Vec::new(); series.len()];
        let shape_beta = joint_fit(series, axis, &shape, &none, true);
        let explained: Vec<Vec<f64>> = series
            .iter()
            .map(|s| {
                (0..s.residual[axis].len())
                    .map(|i| {
                        shape
                            .iter()
                            .zip(&shape_beta)
                            .map(|(&t, b)| b * s.terms[t][axis][i])
                            .sum()
                    })
                    .collect()
            })
            .collect();
        let offset_beta = joint_fit(series, axis, &offset, &explained, false);
        for (&t, &b) in shape
            .iter()
            .zip(&shape_beta)
            .chain(offset.iter().zip(&offset_beta))
        {
            coefficient[t][axis] = b as f32;
        }
    }
    coefficient
}

/// The guard's folds over `activations`: whole series together ([`crate::roles::series_key`]),
/// [`FOLDS`] of them; activation by activation when there are fewer series than folds.
fn series_folds_of(activations: &[&Segment]) -> (Vec<usize>, usize) {
    let mut keys: Vec<_> = activations
        .iter()
        .map(|s| crate::roles::series_key(s))
        .collect();
    keys.sort();
    keys.dedup();
    if keys.len() >= FOLDS {
        let fold_of = activations
            .iter()
            .map(|s| {
                keys.binary_search(&crate::roles::series_key(s))
                    .unwrap_or(0)
                    % FOLDS
            })
            .collect();
        (fold_of, FOLDS)
    } else {
        let folds = FOLDS.clamp(2, activations.len().max(2));
        ((0..activations.len()).map(|i| i % folds).collect(), folds)
    }
}

/// One held-out activation's evidence on one axis.
struct HeldOutGain {
    /// Mean square of the 1-s residual without the term less with it, (°/s)².
    squared: f64,
    /// The paper's drift metric without the term less with it, °/s.
    drift: f64,
    /// The drift metric without the term, °/s.
    drift_before: f64,
    /// The mean square without the term, (°/s)².
    squared_before: f64,
}

/// Whether a term's kind changes the shape within an activation (judged by the drift) rather than
/// the offsets between activations (judged by the squared residual), whatever its channel does:
/// every kind but an auxiliary input ([`ChosenTerm::shape`]).
fn changes_shape(term: Term) -> bool {
    !matches!(term, Term::Aux { .. })
}

/// The guard's evidence for adding `term` to each axis's admitted terms: per axis and training
/// activation, the held-out gains (squared error, and the paper's drift metric, of the model
/// without the term less with it) and the drift metric without it; both models are fitted —
/// coefficients and refitted tables — without the held-out activations' fold. This measures the
/// model firmware would run, not a linear stand-in: a coefficient fitted on a small left-over part
/// can be large, and the refitted tables then cancel most, not all, of it.
#[allow(clippy::too_many_arguments)]
fn held_out_gains(
    base: &FittedUnit,
    keying: &Keying,
    plan: &TermPlan,
    centre: &[[f32; 3]],
    calibration: &[&Segment],
    training: &[&Segment],
    series: &[TrainingSeries],
    admitted: &[Vec<usize>; 3],
    term: usize,
    settings: &FitSettings,
) -> Result<[Vec<HeldOutGain>; 3], FitError> {
    let with: [Vec<usize>; 3] = admitted
        .clone()
        .map(|a| a.into_iter().chain([term]).collect());
    let (fold_of, folds) = series_folds_of(training);
    let mut gains: [Vec<HeldOutGain>; 3] = Default::default();
    for fold in 0..folds {
        let train: Vec<&TrainingSeries> = series
            .iter()
            .zip(&fold_of)
            .filter(|(_, &f)| f != fold)
            .map(|(s, _)| s)
            .collect();
        let held_out: Vec<&Segment> = training
            .iter()
            .zip(&fold_of)
            .filter(|(_, &f)| f == fold)
            .map(|(s, _)| *s)
            .collect();
        let held_out_errors = |chosen: &[Vec<usize>; 3]| -> Result<Vec<[(f64, f64); 3]>, FitError> {
            let extension = plan.extension(centre, &coefficients(plan, &train, chosen));
            let (_, tables) = refit(base, keying, plan, &extension, calibration, settings)?;
            Ok(held_out
                .par_iter()
                .map(|s| errors(&tables, keying, plan, s, settings))
                .collect())
        };
        let (without, with) = (held_out_errors(admitted)?, held_out_errors(&with)?);
        for (before, after) in without.iter().zip(&with) {
            for axis in 0..3 {
                gains[axis].push(HeldOutGain {
                    squared: before[axis].0 - after[axis].0,
                    drift: before[axis].1 - after[axis].1,
                    drift_before: before[axis].1,
                    squared_before: before[axis].0,
                });
            }
        }
    }
    Ok(gains)
}

/// The extended model of one unit and how it was reached.
#[derive(Debug, Clone)]
pub struct Extended {
    /// Tables refitted with the terms' contribution removed, carrying the admitted terms, stage 3
    /// keyed per axis as the loop chose ([`Keying`]: the history-keyed axes need firmware that
    /// starts with `power_on_after`).
    pub tables: ModifiedTables,
    /// The terms that were admitted on at least one axis (which auxiliary channel is which input).
    pub plan: TermPlan,
    /// The guard's decision for every proposed term on every axis.
    pub admissions: Vec<Admission>,
    /// The unit refitted with the terms' contribution removed (its baselines are unchanged).
    pub refitted: FittedUnit,
}

/// Fits the extended model of one unit: `plan`'s terms (from the diagnosis) are admitted on an
/// axis one at a time, in order, only if they lower the residual of the refitted model on held-out
/// `training` activations (cross-validated by activation, one-sided test, family-wise 5 % over
/// every term and axis); the admitted
/// terms' coefficients are fitted on all `training` activations against what the tables leave of
/// each term ([`Absorber`]), and the tables are refitted once on `calibration` with the terms'
/// contribution removed. With nothing admitted the paper's tables come back unchanged. Stage 3 is
/// keyed per axis as `keying` says, throughout: the base model, the absorbers and the refits. A
/// rate term's filter starts at `switch_on_rate` (without the heating for the element's rate).
pub fn extend(
    base: &FittedUnit,
    keying: &Keying,
    plan: &TermPlan,
    switch_on_rate: &[SwitchOnRateFit; 3],
    calibration: &[&Segment],
    training: &[&Segment],
    settings: &FitSettings,
) -> Result<Extended, FitError> {
    let core_settings = *base.modified.settings();
    // The element has not started heating at switch-on: its rate starts at the cooling alone.
    let start = |fit: &SwitchOnRateFit| match plan.element_rate {
        Some(true) => without_heating(fit.rate),
        _ => fit.rate,
    };
    let plan = &TermPlan {
        switch_on_rate: std::array::from_fn(|a| start(&switch_on_rate[a])),
        ..plan.clone()
    };
    let references = reference_indices(&base.modified, settings);
    let absorbers = (0..plan.terms.len())
        .map(|t| {
            Absorber::fit(
                calibration,
                |s| {
                    let on = switch_on_raw(s, settings);
                    term_values(plan, &core_settings, s, on, keying.previous(s))
                        .into_iter()
                        .nth(t)
                },
                settings,
                keying,
                &references,
            )?
            .ok_or_else(|| FitError::Insufficient {
                unit: base.unit_id.clone(),
                what: format!(
                    "no calibration activation carries the inputs of term `{}`",
                    plan.terms[t].candidate
                ),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let base_tables = keying.tables(&base.modified, &base.by_history);
    let series: Vec<TrainingSeries> = training
        .par_iter()
        .map(|s| training_series(&base_tables, keying, plan, &absorbers, s, settings))
        .collect();

    let centre: Vec<[f32; 3]> = (0..plan.terms.len())
        .map(|t| {
            std::array::from_fn(|axis| {
                let (sum, n) = series
                    .iter()
                    .map(|s| s.raw_sum[t][axis])
                    .fold((0.0, 0), |(a, m), (b, k)| (a + b, m + k));
                (sum / n.max(1) as f64) as f32
            })
        })
        .collect();
    // Forward selection, the diagnosis's order: a term joins an axis only if the model with it
    // beats the model without it on held-out activations.
    let mut admissions = Vec::new();
    let mut admitted: [Vec<usize>; 3] = Default::default();
    for (t, chosen) in plan.terms.iter().enumerate() {
        let gains = held_out_gains(
            base,
            keying,
            plan,
            &centre,
            calibration,
            training,
            &series,
            &admitted,
            t,
            settings,
        )?;
        for (axis, gains) in gains.iter().enumerate() {
            let squared: Vec<f64> = gains.iter().map(|g| g.squared).collect();
            let (improvement, p_value) = crate::statistics::one_sided_mean_test(&squared);
            let drift: Vec<f64> = gains.iter().map(|g| g.drift).collect();
            let (drift_gain, drift_p_value) = crate::statistics::one_sided_mean_test(&drift);
            // Bonferroni over every (term, axis) pair: the guard is a test like the diagnosis.
            let level = ADMIT_ALPHA / (3 * plan.terms.len()).max(1) as f64;
            let drift_before =
                gains.iter().map(|g| g.drift_before).sum::<f64>() / gains.len().max(1) as f64;
            // Where the diagnosis found the term significant, it needs no significance of its
            // own on the held-out folds: it is admitted unless they say it makes things worse —
            // a mean loss on the metric it is for, or a significant one (one-sided, 5 %) on the
            // other. A right, significant candidate that waited for a Bonferroni-level gain of its
            // own on a few dozen activations went unadmitted on every axis it was found on; one
            // admitted on "not significantly worse" alone let a neighbour's rise and rise² in
            // where the element's lag was the effect (their held-out drift went up, by little).
            let squared_worse = improvement < 0.0 && 1.0 - p_value < ADMIT_ALPHA;
            let drift_worse =
                drift_gain < -0.01 * drift_before && 1.0 - drift_p_value < ADMIT_ALPHA;
            let (admit, reason) = if chosen.found_on[axis] {
                let (own_gain, own_metric) = if chosen.shape {
                    (drift_gain, "drift")
                } else {
                    (improvement, "squared residual")
                };
                // A found term must not make the guard's activations worse on either metric: a
                // mean loss of more than 1 % of a metric refuses it, significant or not (a rate
                // term with a long time constant cut the drift on a null unit while its start
                // moved the offsets: the held-out RMS rose by a fifth).
                let squared_before =
                    gains.iter().map(|g| g.squared_before).sum::<f64>() / gains.len().max(1) as f64;
                let squared_worse = squared_worse || improvement < -0.01 * squared_before;
                let drift_worse = drift_worse || drift_gain < -0.01 * drift_before;
                let admit = own_gain > 0.0 && !squared_worse && !drift_worse;
                let reason = if admit {
                    format!("significant in the diagnosis on this axis, and lowers the held-out {own_metric}")
                } else if own_gain <= 0.0 {
                    format!("significant in the diagnosis, but the held-out {own_metric} does not fall with it")
                } else if drift_worse {
                    format!(
                        "significant in the diagnosis, but raises the held-out drift by {:.2e} °/s (p {:.3})",
                        -drift_gain,
                        1.0 - drift_p_value
                    )
                } else {
                    format!(
                        "significant in the diagnosis, but raises the held-out squared residual by {:.2e} (°/s)² (p {:.3})",
                        -improvement,
                        1.0 - p_value
                    )
                };
                (admit, reason)
            } else {
                not_found_admission(
                    chosen.shape,
                    (improvement, p_value, squared_worse),
                    (drift_gain, drift_p_value, drift_worse),
                    level,
                )
            };
            if admit {
                admitted[axis].push(t);
            }
            admissions.push(Admission {
                candidate: chosen.candidate.clone(),
                axis: AXIS_NAMES[axis],
                improvement,
                p_value,
                drift_gain_dps: drift_gain,
                drift_p_value,
                admitted: admit,
                reason,
            });
        }
    }
    let all: Vec<&TrainingSeries> = series.iter().collect();
    let coefficient = coefficients(plan, &all, &admitted);
    // Terms no axis admitted are dropped (the firmware computes nothing for them), and so are
    // auxiliary inputs no kept term reads: the inputs are renumbered in order.
    let keep: Vec<usize> = (0..plan.terms.len())
        .filter(|&t| coefficient[t].iter().any(|c| *c != 0.0))
        .collect();
    let kept = plan.keeping(&keep);
    let extension = kept.extension(
        &keep.iter().map(|&t| centre[t]).collect::<Vec<_>>(),
        &keep.iter().map(|&t| coefficient[t]).collect::<Vec<_>>(),
    );
    let (refitted, tables) = refit(base, keying, &kept, &extension, calibration, settings)?;
    Ok(Extended {
        tables,
        plan: kept,
        admissions,
        refitted,
    })
}

/// The guard's decision, and why, for a term on an axis whose diagnosis did not find it: each kind
/// is tested on the metric it is for, at `level`, and refused when it costs the other one
/// significantly. `squared` and `drift`: each metric's held-out gain, its one-sided p-value and
/// whether it got significantly worse.
fn not_found_admission(
    shape: bool,
    squared: (f64, f64, bool),
    drift: (f64, f64, bool),
    level: f64,
) -> (bool, String) {
    let ((improvement, p_value, squared_worse), (drift_gain, drift_p_value, drift_worse)) =
        (squared, drift);
    let admit = if shape {
        // A shape within activations (the element's heating rate, rise², another axis's rise)
        // lowers the drift of every activation while its share of the squared residual, which
        // the offsets between activations dominate, stays in the noise.
        drift_p_value < level && drift_gain > 0.0 && !squared_worse
    } else {
        // An auxiliary input moves offsets (supply, orientation), which the drift cannot see; it
        // may add wiggles within activations: refused when the drift gets worse by more than
        // 1 %. Not "no worse on average": an offset term leaves the metric alone up to noise, and
        // a refit moves it consistently by ~1e-7 °/s.
        p_value < level && improvement > 0.0 && !drift_worse
    };
    let (metric, p) = if shape {
        ("drift", drift_p_value)
    } else {
        ("squared residual", p_value)
    };
    let reason = if admit {
        format!(
            "not found on this axis, but lowers the held-out {metric} (p {p:.1e} < {level:.1e})"
        )
    } else if squared_worse || drift_worse {
        "not found on this axis, and makes the held-out data worse".to_owned()
    } else {
        format!("not found on this axis, and its held-out {metric} gain is not significant (p {p:.3}, needs < {level:.1e} over every term and axis)")
    };
    (admit, reason)
}

/// `segment` with the extension's contribution taken out of its rates (what the tables should
/// see once the extra terms explain their part).
fn without_terms(
    extension: &Extension,
    plan: &TermPlan,
    core_settings: &Settings,
    segment: &Segment,
    keying: &Keying,
    settings: &FitSettings,
) -> Segment {
    let switch_on = switch_on_raw(segment, settings);
    let values = term_values(
        plan,
        core_settings,
        segment,
        switch_on,
        keying.previous(segment),
    );
    let mut adjusted = segment.clone();
    for (axis, rates) in adjusted.rate_dps.iter_mut().enumerate() {
        for (t, term) in extension.terms.iter().enumerate() {
            let Some(column) = values.get(t) else {
                continue;
            };
            let (c, centre) = (term.coefficient[axis], term.centre[axis]);
            if c == 0.0 {
                continue;
            }
            for (rate, &v) in rates.iter_mut().zip(&column[axis]) {
                let extra = c * (v - centre);
                if extra.is_finite() {
                    *rate -= extra;
                }
            }
        }
    }
    adjusted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::{CandidateScore, BETWEEN_ACTIVATIONS, WITHIN_ACTIVATIONS};

    fn axis(name: &'static str, ranking: &[(&str, bool)]) -> AxisDiagnosis {
        AxisDiagnosis {
            axis: name,
            activations: 10,
            residual_rms_dps: 0.01,
            detectable_share: 0.2,
            size_threshold: 0.1,
            response_size_threshold: 0.1,
            baseline: Vec::new(),
            baseline_explained_within: 0.0,
            baseline_explained_between: 0.0,
            selected: Vec::new(),
            ranking: ranking
                .iter()
                .map(|(candidate, significant)| CandidateScore {
                    name: (*candidate).to_owned(),
                    explained: 0.5,
                    p_value: 0.001,
                    whole_p_value: 0.001,
                    drift_p_value: 1.0,
                    family_p_value: if *significant { 0.01 } else { 0.5 },
                    significant: *significant,
                    coefficient: 0.01,
                    stable: true,
                    absorbed_by_model: 0.0,
                    // A channel's offsets, the temperatures' shapes, as the diagnosis mostly
                    // finds them.
                    level: if candidate.starts_with("aux:") {
                        BETWEEN_ACTIVATIONS
                    } else {
                        WITHIN_ACTIVATIONS
                    },
                    thermal_response: Kind::is_thermal_response(candidate),
                })
                .collect(),
        }
    }

    #[test]
    fn significant_candidates_become_terms_once_best_ranks_first() {
        let axes = [
            axis(
                "X",
                &[
                    ("temperature rate X (τ 30 s)", true),
                    ("aux:supply_voltage", true),
                ],
            ),
            axis(
                "Y",
                &[
                    // drift-core keeps one rate filter per axis: the best-ranked τ wins.
                    ("temperature rate Y (τ 8 s)", true),
                    ("campaign time (ageing)", true),
                ],
            ),
            axis("Z", &[("rise X", true), ("rise² Z", false)]),
        ];
        let plan = TermPlan::choose(&axes);
        let terms: Vec<Term> = plan.terms.iter().map(|t| t.term).collect();
        assert_eq!(
            terms,
            [
                Term::TemperatureRate {
                    time_constant_ms: 30_000
                },
                Term::AxisRise { axis: 0 },
                Term::Aux {
                    input: 0,
                    time_constant_ms: AUX_TIME_CONSTANT_MS
                },
            ]
        );
        assert_eq!(plan.aux_inputs, ["supply_voltage"]);
        assert_eq!(
            plan.terms[0].candidate,
            "temperature rate (own axis, τ 30 s)"
        );
        // Ageing and insignificant candidates never become terms.
        assert!(plan.terms.iter().all(|t| !t.candidate.contains("ageing")));
    }

    #[test]
    fn a_vector_component_brings_its_siblings_and_own_axis_kinds_are_named_by_kind() {
        let axes = [
            axis("X", &[("aux:accel_y", true), ("aux:accel_x", false)]),
            axis("Y", &[("rise² Y", true), ("aux:accel_z", false)]),
        ];
        let plan = TermPlan::choose(&axes);
        let names: Vec<&str> = plan.terms.iter().map(|t| t.candidate.as_str()).collect();
        assert_eq!(
            names,
            [
                "aux:accel_y",
                "aux:accel_x",
                "aux:accel_z",
                "rise² (own axis)"
            ]
        );
        assert_eq!(plan.aux_inputs, ["accel_y", "accel_x", "accel_z"]);
    }

    #[test]
    fn keeping_terms_renumbers_the_auxiliary_inputs_they_read() {
        let axes = [axis(
            "X",
            &[("aux:a", true), ("aux:b", true), ("rise² X", true)],
        )];
        let plan = TermPlan::choose(&axes);
        let kept = plan.keeping(&[1, 2]);
        let terms: Vec<Term> = kept.terms.iter().map(|t| t.term).collect();
        assert_eq!(
            terms,
            [
                Term::Aux {
                    input: 0,
                    time_constant_ms: AUX_TIME_CONSTANT_MS
                },
                Term::RiseSquared
            ]
        );
        assert_eq!(kept.aux_inputs, ["b"]);
        assert!(plan.keeping(&[]).terms.is_empty() && plan.keeping(&[]).aux_inputs.is_empty());
    }

    #[test]
    fn a_shape_term_is_fitted_within_activations_and_an_offset_term_on_what_it_leaves() {
        // Ten activations: a rate whose mean differs from one activation to the next (m) and
        // whose shape within each is a ramp, and an auxiliary input constant per activation (v).
        // The residual is 0.5 × the rate's shape, 2 × the input, and −3 × m: an offset per
        // activation that goes with the rate's mean but is not the rate's (the initial bias's to
        // answer). A pooled fit would take the rate's coefficient from that offset.
        let plan = TermPlan::choose(&[axis(
            "X",
            &[("element rate X (τ 30 s)", true), ("aux:supply", true)],
        )]);
        assert!(plan.terms[0].shape && !plan.terms[1].shape);
        let series: Vec<TrainingSeries> = (0..10)
            .map(|a| {
                let m = if a % 2 == 0 { 1.0 } else { -1.0 };
                let v = if a % 4 < 2 { 1.0 } else { -1.0 };
                let shape: Vec<f64> = (0..50).map(|i| f64::from(i) / 50.0 - 0.49).collect();
                let rate: Vec<f64> = shape.iter().map(|s| m + s).collect();
                let residual: Vec<f64> =
                    shape.iter().map(|s| 0.5 * s + 2.0 * v - 3.0 * m).collect();
                let same = |values: Vec<f64>| [values.clone(), values.clone(), values];
                TrainingSeries {
                    residual: same(residual),
                    terms: vec![same(rate), same(vec![v; 50])],
                    raw_sum: Vec::new(),
                }
            })
            .collect();
        let all: Vec<&TrainingSeries> = series.iter().collect();
        let admitted = [vec![0, 1], vec![0], vec![1]];
        let c = coefficients(&plan, &all, &admitted);
        assert!((c[0][0] - 0.5).abs() < 1e-4, "{c:?}");
        assert!((c[1][0] - 2.0).abs() < 1e-3, "{c:?}");
        // Alone, each kind gets the same; a term not admitted on an axis stays 0.
        assert!((c[0][1] - 0.5).abs() < 1e-4 && c[1][1] == 0.0, "{c:?}");
        assert!(c[0][2] == 0.0 && (c[1][2] - 2.0).abs() < 1e-3, "{c:?}");
    }

    #[test]
    fn the_best_rate_candidate_sets_the_filters_start_and_a_rate_started_otherwise_is_refused() {
        let axes = [
            axis("X", &[("element rate X (τ 30 s)", true)]),
            // The same τ started as the sensor's rate: the one filter cannot start both ways.
            axis(
                "Y",
                &[("temperature rate Y (τ 30 s)", true), ("rise² Y", true)],
            ),
        ];
        let plan = TermPlan::choose(&axes);
        let names: Vec<&str> = plan.terms.iter().map(|t| t.candidate.as_str()).collect();
        assert_eq!(
            names,
            ["element rate (own axis, τ 30 s)", "rise² (own axis)"]
        );
        assert_eq!(plan.element_rate, Some(true));
        let sensor = TermPlan::choose(&[axis("Y", &[("temperature rate Y (τ 8 s)", true)])]);
        assert_eq!(sensor.element_rate, Some(false));
        // Dropping the rate term drops its start too.
        assert_eq!(plan.keeping(&[1]).element_rate, None);
        assert_eq!(plan.keeping(&[0]).element_rate, Some(true));
        assert_eq!(
            TermPlan::choose(&[axis("X", &[("rise² X", true)])]).element_rate,
            None
        );
    }

    #[test]
    fn nothing_significant_offers_nothing_and_at_most_four() {
        let quiet = [axis("X", &[("aux:supply_voltage", false)])];
        assert!(TermPlan::choose(&quiet).terms.is_empty());
        // A rate that is not significant is not offered either.
        let rates = [
            axis("X", &[("temperature rate X (τ 8 s)", false)]),
            axis("Y", &[("temperature rate Y (τ 30 s)", false)]),
        ];
        assert!(TermPlan::choose(&rates).terms.is_empty());
        let many = [axis(
            "X",
            &[
                ("aux:a", true),
                ("aux:b", true),
                ("aux:c", true),
                ("aux:d", true),
                ("aux:e", true),
                ("rise² X", true),
            ],
        )];
        let plan = TermPlan::choose(&many);
        assert_eq!(plan.terms.len(), MAX_TERMS);
        assert_eq!(plan.aux_inputs, ["a", "b", "c", "d"]);
        // The guard judges a shape by the drift and an auxiliary input by the squared residual.
        assert!(changes_shape(Term::RiseSquared));
        assert!(!changes_shape(plan.terms[0].term) && !plan.terms[0].shape);
    }

    #[test]
    fn an_input_found_within_activations_is_fitted_and_judged_as_a_shape() {
        // The residual is 2 × a channel's variation within each activation, plus offsets between
        // activations that go against the channel's mean (the switch-on offsets' scatter, which
        // the initial bias answers). Found within activations, the channel is a shape term and
        // gets 2; fitted on the offsets it would take its coefficient from them.
        let mut found = axis("X", &[("aux:humidity", true)]);
        found.ranking[0].level = WITHIN_ACTIVATIONS;
        let plan = TermPlan::choose(&[found]);
        assert!(plan.terms[0].shape && !changes_shape(plan.terms[0].term));
        let series: Vec<TrainingSeries> = (0..10)
            .map(|a| {
                let m = f64::from(a) - 4.5;
                let shape: Vec<f64> = (0..50).map(|i| f64::from(i) / 50.0 - 0.49).collect();
                let channel: Vec<f64> = shape.iter().map(|s| m + s).collect();
                let residual: Vec<f64> = shape.iter().map(|s| 2.0 * s - 5.0 * m).collect();
                let same = |values: Vec<f64>| [values.clone(), values.clone(), values];
                TrainingSeries {
                    residual: same(residual),
                    terms: vec![same(channel)],
                    raw_sum: Vec::new(),
                }
            })
            .collect();
        let all: Vec<&TrainingSeries> = series.iter().collect();
        let c = coefficients(&plan, &all, &[vec![0], vec![], vec![]]);
        assert!((c[0][0] - 2.0).abs() < 1e-4, "{c:?}");
        // The same channel found between activations is an offset, fitted on them.
        let offset = TermPlan::choose(&[axis("X", &[("aux:humidity", true)])]);
        assert!(!offset.terms[0].shape);
        let c = coefficients(&offset, &all, &[vec![0], vec![], vec![]]);
        assert!(c[0][0] < 0.0, "{c:?}");
    }
}
