//! Forward selection on one axis, in two steps: the unit's own thermal response, then the
//! effects over it ([`crate::diagnose::diagnose_axis`]); the size thresholds each step's gain must
//! reach besides its shuffle test.

use std::collections::BTreeMap;

use drift_recording::{Interrupted, Progress};
use serde::Serialize;

use crate::permutation::{Null, Scored};

/// At most this many candidates are selected per axis, one after the other into the baseline
/// (drift-core's `MAX_TERMS`).
pub const MAX_SELECTED: usize = drift_core::MAX_TERMS;

/// The practical size a candidate's gain must reach besides its shuffle test, by how many
/// activations the axis is diagnosed on: the 95th percentile of the per-axis top gain over the
/// baseline on null worlds (no effect drawn) of an independent simulator of the unit, where the
/// shuffle test alone is liberal on a structured residual (`../shared/design/closed-loop.md`:
/// ≈ 0.10 on ~100 activations, ≈ 0.14 on half as many). Pairs (at least this many activations,
/// threshold), descending by size. On this repository's own drawn worlds the same percentile is
/// larger (experiments/README.md, *The size threshold*): their units' thermal structure is
/// more than the paper's model represents.
pub const SIZE_THRESHOLDS: [(usize, f64); 2] = [(100, 0.10), (0, 0.14)];

/// The size threshold for an axis diagnosed on `activations` activations ([`SIZE_THRESHOLDS`]).
pub fn size_threshold(activations: usize) -> f64 {
    threshold_at(&SIZE_THRESHOLDS, activations)
}

/// The threshold of a table of (at least this many activations, threshold) pairs, descending.
fn threshold_at(table: &[(usize, f64)], activations: usize) -> f64 {
    table
        .iter()
        .find(|(at_least, _)| activations >= *at_least)
        .map_or(1.0, |(_, tau)| *tau)
}

/// The size threshold an effect's gain must reach, by how many activations the axis is diagnosed
/// on, once the unit's own thermal response is in the baseline: [`SIZE_THRESHOLDS`] itself, the
/// independent simulator's values, kept a name of its own so the steps can be calibrated apart. On
/// null worlds of `drift_sim::world` with a
/// diagnosis campaign shaped like an analyst's they leave 4 of 90 axes with a significant effect
/// (experiments/README.md, *Full size, the unit's own thermal response selected first*); those
/// worlds judged the values and did not set them.
pub const EFFECT_SIZE_THRESHOLDS: [(usize, f64); 2] = SIZE_THRESHOLDS;

/// The size threshold for an effect on an axis diagnosed on `activations` activations
/// ([`EFFECT_SIZE_THRESHOLDS`]).
pub fn effect_size_threshold(activations: usize) -> f64 {
    threshold_at(&EFFECT_SIZE_THRESHOLDS, activations)
}

/// One candidate selected into the baseline, in order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Selected {
    /// Its name.
    pub name: String,
    /// Its cross-validated gain over the baseline and the candidates selected before it.
    pub gain: f64,
    /// Its family-wise p-value in that round.
    pub family_p_value: f64,
    /// Selected as part of the unit's own thermal response ([`Kind::is_thermal_response`](crate::candidates::Kind::is_thermal_response)),
    /// before any effect was sought, rather than as an effect.
    pub thermal_response: bool,
}

/// What every round of one axis's forward selection shares; every slice has one entry per
/// activation.
pub(crate) struct Round<'a> {
    /// The axis (it seeds the shuffles).
    pub axis: usize,
    /// The baseline's column names.
    pub baseline: &'a [String],
    /// Each activation's baseline columns on the axis, by name.
    pub baselines: &'a [&'a BTreeMap<String, Vec<f64>>],
    /// Each activation's residual on the axis.
    pub residuals: &'a [&'a [f64]],
    /// Each activation's candidates on the axis, less what the tables absorb, by name.
    pub candidates: &'a [&'a BTreeMap<String, Vec<f64>>],
    /// Each activation's stratum (unit, set point) and series within it: what the shuffles keep.
    pub strata: &'a [usize],
    pub series: &'a [usize],
    /// Each activation's cross-validation fold, of `folds`.
    pub fold_of: &'a [usize],
    pub folds: usize,
    /// The family-wise significance level.
    pub alpha: f64,
    /// Asked between shuffles whether to go on.
    pub progress: &'a dyn Progress,
}

impl Round<'_> {
    /// Forward selection among `remaining` over the baseline and `selected` (which it extends,
    /// up to [`MAX_SELECTED`] in all): each round scores what is left over both, and the best
    /// candidate joins when it is significant (shuffles) and its gain reaches `threshold`.
    /// Returns the first round's shuffle test (what the ranking reports).
    pub fn select(
        &self,
        mut remaining: Vec<String>,
        selected: &mut Vec<Selected>,
        threshold: f64,
        thermal_response: bool,
    ) -> Result<Null, Interrupted> {
        let axis = self.axis;
        let mut first: Option<Null> = None;
        while selected.len() < MAX_SELECTED && !remaining.is_empty() {
            let columns: Vec<Vec<&[f64]>> = self
                .baselines
                .iter()
                .zip(self.candidates)
                .map(|(baseline, candidates)| {
                    self.baseline
                        .iter()
                        .filter_map(|n| baseline.get(n))
                        .chain(selected.iter().filter_map(|c| candidates.get(&c.name)))
                        .map(Vec::as_slice)
                        .collect()
                })
                .collect();
            let null = Null::measure(
                &Scored {
                    residuals: self.residuals,
                    baseline: &columns,
                    candidates: self.candidates,
                    strata: self.strata,
                    series: self.series,
                    fold_of: self.fold_of,
                    folds: self.folds,
                },
                &remaining,
                // The effect step draws its own shuffles: after a response step that selected
                // nothing it would otherwise replay that step's draws.
                (axis + 3 * selected.len() + if thermal_response { 0 } else { 30 }) as u64,
                self.progress,
            )?;
            let chosen = null
                .observed
                .iter()
                .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
                .map(|(n, (gain, _))| (n.clone(), *gain, null.p_value(*gain)))
                .filter(|&(_, gain, p_value)| {
                    gain > 0.0 && gain >= threshold && p_value <= self.alpha
                });
            if first.is_none() {
                first = Some(null);
            }
            let Some((name, gain, family_p_value)) = chosen else {
                break;
            };
            remaining.retain(|n| *n != name);
            selected.push(Selected {
                family_p_value,
                name,
                gain,
                thermal_response,
            });
        }
        Ok(first.unwrap_or_else(|| Null {
            observed: BTreeMap::new(),
            maxima: Vec::new(),
            baselines: Default::default(),
        }))
    }
}
