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
    Corrector, Extension, ExtensionState, ExtraTerm, Model, ModifiedTables, Term, TermInputs,
    AUX_INPUTS, MAX_TERMS,
};
use drift_recording::Segment;
use serde::Serialize;

use crate::analyse::analyse;
use crate::diagnose::AxisDiagnosis;
use crate::error::FitError;
use crate::evaluate::{sample_at, switch_on_raw};
use crate::fit::{fit_unit, FittedUnit};
use crate::lowpass::centred_moving_average;
use crate::settings::FitSettings;

/// Time constant of the temperature-rate filter, ms: about the 1-s low-pass and ±1 s difference
/// the diagnosis scores the rate with.
pub const RATE_TIME_CONSTANT_MS: u32 = 2000;

const AXIS_NAMES: [&str; 3] = ["X", "Y", "Z"];

/// One extra term chosen from the diagnosis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChosenTerm {
    /// The diagnosis candidate it came from (the first axis that chose it).
    pub candidate: String,
    /// The term's kind, as drift-core computes it.
    #[serde(skip)]
    pub term: Term,
}

/// The extra terms and which recorded auxiliary channel feeds each auxiliary input.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TermPlan {
    /// The terms, in table order.
    pub terms: Vec<ChosenTerm>,
    /// `aux_inputs[i]` is the recording's auxiliary channel the firmware passes as input `i`.
    pub aux_inputs: Vec<String>,
}

impl TermPlan {
    /// The term a diagnosis candidate stands for, if the firmware can compute it per sample.
    /// Time since switch-on, switch-on temperature and the off-time estimate are the table's own
    /// inputs; campaign time is ageing, which no thermal term should model.
    fn term_for(&mut self, candidate: &str) -> Option<Term> {
        if candidate.starts_with("temperature rate ") {
            return Some(Term::TemperatureRate {
                time_constant_ms: RATE_TIME_CONSTANT_MS,
            });
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
        let channel = candidate.strip_prefix("aux:")?;
        let input = match self.aux_inputs.iter().position(|c| c == channel) {
            Some(input) => input,
            None if self.aux_inputs.len() < AUX_INPUTS => {
                self.aux_inputs.push(channel.to_owned());
                self.aux_inputs.len() - 1
            }
            None => return None,
        };
        Some(Term::Aux {
            input: u8::try_from(input).ok()?,
        })
    }

    /// The significant candidates of every axis that map to a term, best ranks first across the
    /// axes, each term once, at most [`MAX_TERMS`]. Empty when nothing significant is left.
    pub fn choose(axes: &[AxisDiagnosis]) -> Self {
        let mut plan = Self::default();
        let deepest = axes.iter().map(|a| a.ranking.len()).max().unwrap_or(0);
        for rank in 0..deepest {
            for axis in axes {
                let Some(candidate) = axis.ranking.get(rank).filter(|c| c.significant) else {
                    continue;
                };
                if plan.terms.len() == MAX_TERMS {
                    return plan;
                }
                // A new auxiliary channel always makes a new term, so the channel list only grows
                // with the terms.
                let new = plan
                    .term_for(&candidate.name)
                    .filter(|term| !plan.terms.iter().any(|t| t.term == *term));
                if let Some(term) = new {
                    plan.terms.push(ChosenTerm {
                        candidate: candidate.name.clone(),
                        term,
                    });
                }
            }
        }
        plan
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
        let mut extension = Extension::NONE;
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

/// Corrects a whole activation with `tables` (extended or not), passing the plan's auxiliary
/// inputs: the firmware's path, sample by sample.
pub fn correct_with_terms<M: Model>(
    tables: &M,
    plan: &TermPlan,
    segment: &Segment,
    switch_on: [f32; 3],
) -> [Vec<f32>; 3] {
    let mut corrected: [Vec<f32>; 3] = Default::default();
    let Ok(mut corrector) = Corrector::new(tables) else {
        return segment.rate_dps.clone();
    };
    if corrector.power_on(switch_on).is_err() {
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

/// Per axis and term, the uncentred term values of every sample, as the corrector computes them
/// (the last good temperature is held through faults).
fn term_values(
    plan: &TermPlan,
    tables: &ModifiedTables,
    segment: &Segment,
    switch_on: [f32; 3],
) -> [Vec<Vec<f32>>; 3] {
    let settings = tables.settings();
    let shape = plan.extension(&[], &[]);
    let mut state = ExtensionState::power_on(switch_on.map(|r| settings.celsius(r)));
    let mut held = switch_on;
    let mut values: [Vec<Vec<f32>>; 3] =
        std::array::from_fn(|_| vec![Vec::with_capacity(segment.len()); plan.terms.len()]);
    for i in 0..segment.len() {
        let sample = sample_at(segment, i);
        for (held, raw) in held.iter_mut().zip(sample.temperature_raw) {
            if raw.is_finite() {
                *held = raw;
            }
        }
        let inputs = TermInputs {
            since_power_on_ms: sample.since_power_on_ms,
            celsius: held.map(|r| settings.celsius(r)),
            rise_celsius: [0, 1, 2].map(|a| (held[a] - switch_on[a]) / settings.raw_per_celsius),
            aux: plan.aux_at(segment, i),
        };
        let row = state.values(&shape, &inputs);
        for (axis, per_term) in values.iter_mut().enumerate() {
            for (term, column) in per_term.iter_mut().enumerate() {
                column.push(row[axis][term]);
            }
        }
    }
    values
}

/// Fits the plan's coefficients: per axis, least squares of the paper model's low-passed residual
/// on the low-passed term values (with an intercept) over every training activation; centres are
/// the training means, so the terms add nothing on average where they were fitted.
pub fn fit_coefficients(
    tables: &ModifiedTables,
    plan: &TermPlan,
    training: &[&Segment],
    settings: &FitSettings,
) -> Extension {
    let k = plan.terms.len();
    let window = settings.lowpass_window_samples;
    let mut rows: [Vec<Vec<f64>>; 3] = Default::default();
    let mut targets: [Vec<f64>; 3] = Default::default();
    // The residual the terms must explain is the paper model's, without any terms.
    let Ok(plain) = tables.clone().with_extension(Extension::NONE) else {
        return plan.extension(&[], &[]);
    };
    for segment in training {
        let switch_on = switch_on_raw(segment, settings);
        let residual = correct_with_terms(&plain, plan, segment, switch_on);
        let values = term_values(plan, tables, segment, switch_on);
        let step = (segment.sample_rate_hz as usize / 10).max(1);
        for axis in 0..3 {
            let y = centred_moving_average(&residual[axis], window);
            let x: Vec<Vec<f64>> = values[axis]
                .iter()
                .map(|v| centred_moving_average(v, window))
                .collect();
            for i in (0..y.len()).step_by(step) {
                let row: Vec<f64> = x.iter().map(|column| column[i]).collect();
                if y[i].is_finite() && row.iter().all(|v| v.is_finite()) {
                    rows[axis].push(row);
                    targets[axis].push(y[i]);
                }
            }
        }
    }
    let mut centre = vec![[0.0f32; 3]; k];
    let mut coefficient = vec![[0.0f32; 3]; k];
    for axis in 0..3 {
        let n = rows[axis].len();
        if n <= k + 1 {
            continue;
        }
        let means: Vec<f64> = (0..k)
            .map(|t| rows[axis].iter().map(|r| r[t]).sum::<f64>() / n as f64)
            .collect();
        let design: Vec<Vec<f64>> = rows[axis]
            .iter()
            .map(|r| {
                std::iter::once(1.0)
                    .chain(r.iter().zip(&means).map(|(v, m)| v - m))
                    .collect()
            })
            .collect();
        let beta = crate::diagnose::least_squares(&design, &targets[axis]);
        for t in 0..k {
            centre[t][axis] = means[t] as f32;
            coefficient[t][axis] = beta.get(t + 1).copied().unwrap_or(0.0) as f32;
        }
    }
    plan.extension(&centre, &coefficient)
}

/// `segment` with the extension's contribution taken out of its rates (what the tables should
/// see once the extra terms explain their part).
fn without_terms(
    extension: &Extension,
    plan: &TermPlan,
    tables: &ModifiedTables,
    segment: &Segment,
    settings: &FitSettings,
) -> Segment {
    let switch_on = switch_on_raw(segment, settings);
    let values = term_values(plan, tables, segment, switch_on);
    let mut adjusted = segment.clone();
    for (axis, rates) in adjusted.rate_dps.iter_mut().enumerate() {
        for (i, rate) in rates.iter_mut().enumerate() {
            let mut row = [[0.0f32; MAX_TERMS]; 3];
            for (t, column) in values[axis].iter().enumerate() {
                if let (Some(slot), Some(term)) = (row[axis].get_mut(t), extension.terms.get(t)) {
                    *slot = column[i] - term.centre[axis];
                }
            }
            let extra = extension.bias(&row)[axis];
            if extra.is_finite() {
                *rate -= extra;
            }
        }
    }
    adjusted
}

/// The extended model of one unit and how it was reached.
#[derive(Debug, Clone)]
pub struct Extended {
    /// Tables refitted with the terms' contribution removed, carrying the terms.
    pub tables: ModifiedTables,
    /// The plan the terms follow (which auxiliary channel is which input).
    pub plan: TermPlan,
    /// The unit refitted in the last round (its baselines are unchanged by the terms).
    pub refitted: FittedUnit,
}

/// Alternates `rounds` times: fit the coefficients on `training` with the current tables, then
/// refit the tables on `calibration` with the terms' contribution removed.
pub fn extend(
    base: &FittedUnit,
    plan: &TermPlan,
    calibration: &[&Segment],
    training: &[&Segment],
    settings: &FitSettings,
    rounds: usize,
) -> Result<Extended, FitError> {
    let mut tables = base.modified.clone();
    let mut refitted = base.clone();
    let mut extension = fit_coefficients(&tables, plan, training, settings);
    for _ in 0..rounds {
        let analysed = calibration
            .iter()
            .map(|s| {
                analyse(
                    &without_terms(&extension, plan, &tables, s, settings),
                    settings,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        refitted = fit_unit(&analysed, settings)?;
        tables = refitted.modified.clone();
        extension = fit_coefficients(&tables, plan, training, settings);
    }
    let tables = tables
        .with_extension(extension)
        .map_err(|source| FitError::Table {
            unit: base.unit_id.clone(),
            model: "extended",
            source,
        })?;
    Ok(Extended {
        tables,
        plan: plan.clone(),
        refitted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::CandidateScore;

    fn axis(name: &'static str, ranking: &[(&str, bool)]) -> AxisDiagnosis {
        AxisDiagnosis {
            axis: name,
            activations: 10,
            residual_rms_dps: 0.01,
            ranking: ranking
                .iter()
                .map(|(candidate, significant)| CandidateScore {
                    name: (*candidate).to_owned(),
                    explained: 0.5,
                    p_value: 0.001,
                    significant: *significant,
                    coefficient: 0.01,
                    absorbed_by_model: 0.0,
                    level: "within activations",
                })
                .collect(),
        }
    }

    #[test]
    fn significant_candidates_become_terms_once_best_ranks_first() {
        let axes = [
            axis(
                "X",
                &[("temperature rate X", true), ("aux:supply_voltage", true)],
            ),
            axis(
                "Y",
                &[
                    ("temperature rate Y", true),
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
                    time_constant_ms: RATE_TIME_CONSTANT_MS
                },
                Term::AxisRise { axis: 0 },
                Term::Aux { input: 0 },
            ]
        );
        assert_eq!(plan.aux_inputs, ["supply_voltage"]);
        // Ageing and insignificant candidates never become terms.
        assert!(plan.terms.iter().all(|t| !t.candidate.contains("ageing")));
    }

    #[test]
    fn nothing_significant_means_no_terms_and_at_most_four() {
        let quiet = [axis("X", &[("temperature rate X", false)])];
        assert!(TermPlan::choose(&quiet).terms.is_empty());
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
    }
}
