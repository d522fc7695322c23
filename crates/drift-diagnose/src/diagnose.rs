//! Diagnosis: after correction by the paper's model, is a systematic effect left in the residual,
//! and which recorded or derived quantity explains it?
//!
//! For every diagnosed activation, the corrected rate's low-frequency residual is put on a coarse
//! grid beside candidate explanations ([`crate::candidates`]): every auxiliary channel the
//! recording has (whatever its name) and derived quantities (temperature rate per axis, rise², the
//! other axes' rises, time since switch-on, switch-on temperature, residual heat at switch-on,
//! campaign time). Before scoring, each candidate is stripped of what the paper's model already
//! accounts for: the paper's tables are fitted to the candidate itself on the calibration
//! activations ([`crate::absorb`]) and what they predict of it is taken out. A candidate the table
//! explains is then left with nothing to explain, and what is left is exactly what a term in that
//! candidate would add to the paper's model.
//!
//! Score: out-of-sample explained share of the residual's variance for a one-coefficient linear
//! term, cross-validated by series (whole series of activations held out together, never samples
//! or single activations of a series), at the better of two levels (shapes within activations,
//! offsets between them), and 0 unless every fold's coefficient has the same sign. Significance:
//! family-wise, by shuffling the candidates among activations of the same unit and set point
//! ([`crate::permutation`]): a candidate is significant when the best of all candidates reached its
//! share in at most `alpha` of the shuffles. That corrects for the number of candidates, their
//! correlation and the autocorrelation inside activations as they are on the data diagnosed, and
//! gives per axis the smallest share these activations can show ([`AxisDiagnosis::detectable_share`]).
//! The per-activation t-tests (of the squared residual at the candidate's level, of the whole
//! residual, of the drift) are reported beside it.
//!
//! The model whose residual is diagnosed is the loop's: the paper's tables with stage 3 keyed by
//! rise or by heating history per axis, as [`crate::closing`] chose ([`Keying`]).

use std::collections::BTreeMap;

use drift_core::SwitchOnRate;
use drift_recording::{Interrupted, Progress, Segment, SegmentLabels, Within};
use rayon::prelude::*;
use serde::Serialize;

use crate::absorb::Absorber;
use crate::candidates::{Kind, AMBIENT_CHANNEL, SET_POINT_CHANNEL};
use crate::keying::Keying;
use crate::permutation::Level;
use crate::selection::{effect_size_threshold, size_threshold, Round, Selected};
use crate::statistics::one_sided_mean_test;
use crate::switch_on_rate::start_rates;
use drift_evaluate::evaluate::{
    correct_segment_after, correct_segment_at_ambient, spread, switch_on_raw,
};
use drift_fit::error::FitError;
use drift_fit::fit::{reference_indices, FittedUnit};
use drift_fit::lowpass::centred_moving_average;
use drift_fit::settings::FitSettings;

/// Spacing of the diagnosis grid, ms: the residual and the candidates are 1-s means, so two
/// points per window keep what least squares on them needs, at a fifth of a 10-Hz grid's cost.
pub const GRID_MS: u32 = 500;
const AXES: [&str; 3] = ["X", "Y", "Z"];

/// One activation on the diagnosis grid.
#[derive(Debug, Clone)]
pub struct ActivationSeries {
    /// Labels.
    pub labels: SegmentLabels,
    /// Low-frequency residual after the paper's model, per axis, °/s.
    pub residual_dps: [Vec<f64>; 3],
    /// Candidates per axis, by name, as recorded or derived.
    pub candidates: [BTreeMap<String, Vec<f64>>; 3],
    /// The same candidates less what the paper's tables predict of them: what is scored.
    pub left_over: [BTreeMap<String, Vec<f64>>; 3],
    /// The baseline's columns per axis, by name: the paper model's known gaps (the tables read at
    /// the logged ambient, [`AMBIENT_TERM`]; the switch-on temperature and residual heat,
    /// [`Kind::is_known_gap`]) and the bench's context channels, less what the tables predict of
    /// them. Fitted before any candidate; never ranked, never a term.
    pub baseline: [BTreeMap<String, Vec<f64>>; 3],
}

/// The baseline column of the paper model's ambient gap: what the tables predict with stage 2 read
/// at the chamber air logged at switch-on, less what they predict read at the switch-on
/// temperature (the paper's ambient, which after short off-times and under ramps is not the
/// ambient).
pub const AMBIENT_TERM: &str = "ambient term (tables at the logged air)";

/// Low-pass at the fit's window and sample on the diagnosis grid.
fn on_grid<T: Copy + Into<f64>>(values: &[T], window: usize, step: usize) -> Vec<f64> {
    centred_moving_average(values, window)
        .into_iter()
        .step_by(step)
        .collect()
}

/// Puts activations of one unit on the diagnosis grid, with the loop's model (the paper's tables
/// fitted on its calibration activations, stage 3 keyed as chosen) and, for every candidate, what
/// those tables absorb of it.
pub struct Diagnoser {
    settings: FitSettings,
    /// How stage 3 reads each axis of the model diagnosed, and what firmware kept before each
    /// activation.
    keying: Keying,
    /// The diagnosed model's tables (the paper's, with the history-keyed axes `keying` chose).
    tables: Box<drift_core::ModifiedTables>,
    /// Each candidate kind with the tables fitted to it; a kind the calibration activations cannot
    /// carry (an auxiliary channel they lack) is not offered.
    kinds: Vec<(Kind, Absorber)>,
    /// The bench's context channels' kinds, with the tables fitted to each: the baseline's.
    context: Vec<(Kind, Absorber)>,
    /// The paper's tables (stage 3 by rise): what the ambient term reads at the logged air.
    paper: Box<drift_core::ModifiedTables>,
    /// Each axis's rate at switch-on measured on the calibration, where a rate candidate's filter
    /// starts, as the firmware's term would.
    switch_on_rate: [SwitchOnRate; 3],
}

impl Diagnoser {
    /// Learns what the paper's tables absorb of every candidate, on the activations `fitted` was
    /// fitted on. Candidates are the auxiliary channels every calibration activation has and the
    /// derived quantities.
    ///
    /// The model diagnosed is the paper's with stage 3 keyed as `keying` says per axis; a rate
    /// candidate's filter starts at `switch_on_rate` (measured on the same calibration,
    /// [`crate::switch_on_rate::fit_switch_on_rate`]), as the firmware's term would. Channels in
    /// `bench_channels` describe the bench, not the unit, and are not candidates.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        fitted: &FittedUnit,
        calibration: &[&Segment],
        settings: &FitSettings,
        keying: Keying,
        switch_on_rate: [SwitchOnRate; 3],
        bench_channels: &[String],
    ) -> Result<Self, FitError> {
        let mut channels: Vec<String> = calibration
            .first()
            .map(|s| s.aux.keys().cloned().collect())
            .unwrap_or_default();
        channels.retain(|c| calibration.iter().all(|s| s.aux.contains_key(c)));
        // The residual heat reads the chamber set point (the bench's reference for the ambient);
        // the set point itself, like every bench channel, is never a candidate. The other bench
        // channels (the chamber air) are the baseline's context: what follows them is taken out
        // before any candidate is scored.
        let has_set_point = channels.iter().any(|c| c == SET_POINT_CHANNEL);
        // The set point among them: in a field recording it logs the ambient the bench went
        // through, ramps included.
        let context_channels: Vec<String> = channels
            .iter()
            .filter(|c| bench_channels.contains(c))
            .cloned()
            .collect();
        let core = fitted.modified.settings;
        // Each channel's mean over every calibration sample: where its interactions are centred.
        let centred = |c: String| {
            let (sum, n) = calibration
                .iter()
                .filter_map(|s| s.aux.get(&c))
                .flat_map(|channel| channel.values.iter())
                .filter(|v| v.is_finite())
                .fold((0.0, 0usize), |(sum, n), &v| (sum + f64::from(v), n + 1));
            let centre = sum / n.max(1) as f64;
            (c, centre)
        };
        // The drift fit's reference times: each candidate is taken out by the paper's own
        // operator (`Absorber::fit`).
        let references = reference_indices(&fitted.modified, settings);
        // A kind no calibration activation carries (an empty channel) is not offered.
        let absorb = |kinds: Vec<Kind>| {
            kinds
                .into_iter()
                .filter_map(|kind| {
                    let absorber = Absorber::fit(
                        calibration,
                        |s| {
                            let on = switch_on_raw(s, settings);
                            let start = start_rates(&switch_on_rate, &core, on, keying.previous(s));
                            kind.values(s, on, &start)
                        },
                        settings,
                        &keying,
                        &references,
                    );
                    absorber.transpose().map(|a| a.map(|a| (kind, a)))
                })
                .collect::<Result<Vec<_>, FitError>>()
        };
        let candidates = channels
            .into_iter()
            .filter(|c| !bench_channels.contains(c))
            .map(centred);
        // The switch-on temperature and the residual heat are the paper model's own offset gap
        // (its turn-on bias read from a switch-on temperature that residual heat and ramps move):
        // on null worlds they topped the offsets between activations. They join the baseline.
        let (gaps, kinds): (Vec<Kind>, Vec<Kind>) = Kind::all(candidates, has_set_point)
            .into_iter()
            .partition(Kind::is_known_gap);
        let kinds = absorb(kinds)?;
        let mut context_kinds = Kind::context(context_channels.into_iter().map(centred));
        context_kinds.extend(gaps);
        let context = absorb(context_kinds)?;
        Ok(Self {
            settings: settings.clone(),
            tables: keying.tables(&fitted.modified, &fitted.by_history),
            keying,
            kinds,
            context,
            paper: Box::new(fitted.modified.clone()),
            switch_on_rate,
        })
    }

    /// Puts one activation, corrected by the paper's model, on the diagnosis grid.
    pub fn series(&self, segment: &Segment) -> ActivationSeries {
        let window = self.settings.lowpass_window(segment.sample_rate_hz);
        let step = (segment.sample_rate_hz as usize * GRID_MS as usize / 1000).max(1);
        let switch_on = switch_on_raw(segment, &self.settings);
        let (corrected, _) = self.keying.correct(&self.tables, segment, switch_on);
        let start = start_rates(
            &self.switch_on_rate,
            &self.tables.settings,
            switch_on,
            self.keying.previous(segment),
        );
        let residual: [Vec<f64>; 3] = [0, 1, 2].map(|a| on_grid(&corrected[a], window, step));
        let mut candidates: [BTreeMap<String, Vec<f64>>; 3] = Default::default();
        let mut left_over: [BTreeMap<String, Vec<f64>>; 3] = Default::default();
        let mut baseline: [BTreeMap<String, Vec<f64>>; 3] = Default::default();
        let left = |kinds: &[(Kind, Absorber)]| -> Vec<(usize, Axes, Axes)> {
            kinds
                .par_iter()
                .enumerate()
                .filter_map(|(k, (kind, absorber))| {
                    let values = kind.values(segment, switch_on, &start)?;
                    let left = absorber.left_over(segment, values.clone(), switch_on, &self.keying);
                    Some((k, values, left))
                })
                .collect()
        };
        for (k, values, left) in left(&self.kinds) {
            let kind = &self.kinds[k].0;
            for axis in 0..3 {
                let name = kind.name(axis);
                candidates[axis].insert(name.clone(), on_grid(&values[axis], window, step));
                left_over[axis].insert(name, on_grid(&left[axis], window, step));
            }
        }
        for (k, _, left) in left(&self.context) {
            let kind = &self.context[k].0;
            for (axis, column) in baseline.iter_mut().enumerate() {
                column.insert(kind.name(axis), on_grid(&left[axis], window, step));
            }
        }
        if let Some(term) = ambient_term(&self.paper, segment, switch_on) {
            for (axis, column) in baseline.iter_mut().enumerate() {
                column.insert(AMBIENT_TERM.to_owned(), on_grid(&term[axis], window, step));
            }
        }
        ActivationSeries {
            labels: segment.labels.clone(),
            residual_dps: residual,
            candidates,
            left_over,
            baseline,
        }
    }
}

/// The paper's prediction with stage 2 and the initial bias read at the chamber air logged at
/// switch-on (or the set point channel without one), less its prediction read at the switch-on
/// temperature, per axis and sample, °/s; `None` without either. The air is given to drift-core's
/// switch-on (`power_on_at_ambient`), the firmware option for an instrument that measures its
/// ambient: the time since switch-on and the rise, the tables' other inputs, stay as they were.
pub fn ambient_term(
    paper: &drift_core::ModifiedTables,
    segment: &Segment,
    switch_on: [f32; 3],
) -> Option<[Vec<f32>; 3]> {
    let air = logged_ambient(segment)?;
    let (paper_rates, _) = correct_segment_after(paper, segment, switch_on, None);
    let (air_rates, _) = correct_segment_at_ambient(paper, segment, switch_on, air, None);
    // Corrected = rate − prediction: the difference of the corrections is the difference of the
    // predictions, the other way round.
    Some(std::array::from_fn(|a| {
        paper_rates[a]
            .iter()
            .zip(&air_rates[a])
            .map(|(p, q)| p - q)
            .collect()
    }))
}

/// The ambient the bench logged at `segment`'s switch-on, °C: the chamber air where it was
/// logged; otherwise the set point channel, which a field recording logs as the ambient it went
/// through and a chamber holds to within its ripple. `None` without either, or not finite.
pub fn logged_ambient(segment: &Segment) -> Option<f32> {
    if segment.aux.contains_key(AMBIENT_CHANNEL) {
        segment.aux_at_switch_on(AMBIENT_CHANNEL)
    } else {
        segment.aux_at_switch_on(SET_POINT_CHANNEL)
    }
}

/// One quantity per axis and sample.
type Axes = [Vec<f32>; 3];

/// [`CandidateScore::level`] of a candidate whose gain shows in the shape within activations.
pub const WITHIN_ACTIVATIONS: &str = "within activations";
/// [`CandidateScore::level`] of a candidate whose gain shows in the offsets between activations.
pub const BETWEEN_ACTIVATIONS: &str = "between activations";

/// One candidate's score on one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateScore {
    /// Candidate name.
    pub name: String,
    /// Out-of-sample share of the residual's variance explained at its level beyond the baseline
    /// (for a selected candidate: beyond the baseline and the candidates selected before it),
    /// cross-validated by series; 0 when the folds' coefficients disagree in sign.
    pub explained: f64,
    /// One-sided p-value of the mean held-out improvement (before multiple-comparison correction).
    pub p_value: f64,
    /// One-sided p-value of the mean held-out improvement of the whole residual (offsets and
    /// shape together, no per-activation means taken out): what a firmware term changes.
    pub whole_p_value: f64,
    /// One-sided p-value of the mean held-out reduction of the drift (max − min of the 1-s
    /// residual over each activation) when the candidate's within-activation fit is taken out:
    /// the paper's metric, which a shape term changes and an offset cannot.
    pub drift_p_value: f64,
    /// Family-wise p-value of its explained share: the share of shuffles of the candidates among
    /// activations in which the best of every candidate explained as much
    /// ([`crate::permutation`]).
    pub family_p_value: f64,
    /// Whether `family_p_value` is at most `alpha`.
    pub significant: bool,
    /// Fitted coefficient on all data ((°/s) per candidate unit, on what the tables leave of it).
    pub coefficient: f64,
    /// Every cross-validation fold's coefficient has the same sign: the relation does not hang on
    /// one series.
    pub stable: bool,
    /// Share of the candidate's own variance that the paper's tables, fitted to it on the
    /// calibration activations, predict. Near 1: the table accounts for this quantity, and it is
    /// not scored.
    pub absorbed_by_model: f64,
    /// Where the effect shows: within activations (shape), between activations (offsets), or
    /// absorbed by the model.
    pub level: &'static str,
    /// A term of the unit's own thermal response ([`Kind::is_thermal_response`]): selected
    /// before the effects and scored over the baseline alone; every other candidate is an effect,
    /// scored over the baseline and the thermal response selected.
    pub thermal_response: bool,
}

/// The ranking on one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisDiagnosis {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Activations used.
    pub activations: usize,
    /// RMS of the residual, °/s.
    pub residual_rms_dps: f64,
    /// The gain a candidate must exceed to be selected with these activations: the larger of what
    /// the best of every candidate reaches by chance (shuffles, first round) and the size
    /// threshold. An effect explaining less of the residual's variance beyond the baseline (out of
    /// sample) cannot be told from chance or from the paper model's own structure here.
    pub detectable_share: f64,
    /// The size threshold an effect's gain must reach with this many activations
    /// ([`effect_size_threshold`]).
    pub size_threshold: f64,
    /// The size threshold of the unit's own thermal response with this many activations
    /// ([`size_threshold`]).
    pub response_size_threshold: f64,
    /// The baseline's columns, fitted before any candidate.
    pub baseline: Vec<String>,
    /// Share of the residual's variance within activations the baseline explains out of sample.
    pub baseline_explained_within: f64,
    /// Share of the variance of the activations' mean residuals the baseline explains out of
    /// sample.
    pub baseline_explained_between: f64,
    /// The candidates selected into the baseline, in order, with their gains.
    pub selected: Vec<Selected>,
    /// Candidates, selected first, then by their gain over the baseline in the first round.
    pub ranking: Vec<CandidateScore>,
}

impl AxisDiagnosis {
    /// The winning effect, if any is significant: the first effect selected (the unit's own
    /// thermal response, selected before it, is no finding).
    pub fn chosen(&self) -> Option<&CandidateScore> {
        self.ranking
            .iter()
            .find(|c| !c.thermal_response)
            .filter(|c| c.significant)
    }
}

/// A candidate whose variance the paper's tables explain beyond this share is the table's already.
const ABSORBED: f64 = 0.999;

/// Share of the candidate's variance (about its mean, over every activation) that the paper's
/// tables predict: 1 − var(left over) / var(candidate).
fn absorbed_share(activations: &[ActivationSeries], axis: usize, name: &str) -> f64 {
    let spread = |pick: &dyn Fn(&ActivationSeries) -> Option<&Vec<f64>>| {
        let values: Vec<f64> = activations
            .iter()
            .filter_map(pick)
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        let m = mean(values.iter().copied());
        values.iter().map(|v| (v - m).powi(2)).sum::<f64>()
    };
    let total = spread(&|a| a.candidates[axis].get(name));
    if total <= 0.0 {
        return 1.0; // a constant: nothing left once the intercept is taken out
    }
    (1.0 - spread(&|a| a.left_over[axis].get(name)) / total).max(0.0)
}

/// One point of the scoring data: residual and candidate (left over after the tables).
type Point = (f64, f64);

/// Slope and intercept of `y` on `x` over the finite points of `train`; `None` without spread.
fn line(train: &[&Vec<Point>]) -> Option<(f64, f64)> {
    let points = || {
        train
            .iter()
            .flat_map(|g| g.iter())
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    let n = points().count() as f64;
    if n < 2.0 {
        return None;
    }
    let (mx, my) = (
        points().map(|p| p.1).sum::<f64>() / n,
        points().map(|p| p.0).sum::<f64>() / n,
    );
    let sxx: f64 = points().map(|p| (p.1 - mx).powi(2)).sum();
    let sxy: f64 = points().map(|p| (p.1 - mx) * (p.0 - my)).sum();
    if sxx <= 0.0 {
        return Some((0.0, my));
    }
    let slope = sxy / sxx;
    Some((slope, my - slope * mx))
}

/// A candidate's cross-validated score at one level.
struct Score {
    /// One-sided p-value of the mean held-out reduction of the squared residual.
    p_value: f64,
    /// One-sided p-value of the mean held-out reduction of the drift (max − min over the
    /// activation): the paper's metric, which an offset cannot move.
    drift_p_value: f64,
    coefficient: f64,
    /// Every fold's coefficient has the same sign: the relation does not hang on one series.
    stable: bool,
}

/// Which fold each activation is held out in: whole series together (a series' activations share
/// their unit, set point and off-times, so one held out beside its siblings in the training set
/// would be judged by what it has in common with them), `folds` folds; activation by activation
/// when there are fewer series than folds.
///
/// A series is known by its unit, its recording's *nominal* set point, its kind and its index —
/// never by a measured temperature: in a field session whose ambient ramps, the set point logged
/// at each switch-on differs from activation to activation, and keyed on it a series fell apart
/// into single activations (correlated folds, optimistic gains).
pub fn series_folds(activations: &[ActivationSeries], folds: usize) -> (Vec<usize>, usize) {
    let key = |a: &ActivationSeries| {
        (
            a.labels.unit_id.clone(),
            (a.labels.nominal_set_point_celsius() * 1000.0).round() as i64,
            a.labels.series_kind.as_str(),
            a.labels.series,
        )
    };
    let mut series: Vec<_> = activations.iter().map(key).collect();
    series.sort();
    series.dedup();
    if series.len() >= folds.max(2) {
        let fold = activations
            .iter()
            .map(|a| series.binary_search(&key(a)).unwrap_or(0) % folds)
            .collect();
        (fold, folds)
    } else {
        let folds = folds.clamp(2, activations.len().max(2));
        ((0..activations.len()).map(|i| i % folds).collect(), folds)
    }
}

/// Each activation's stratum for the shuffle test: its unit and nominal set point, so that what
/// differs between units or set points (a channel's level, the ambient) stays paired with the
/// residual it came with.
fn set_point_strata(activations: &[ActivationSeries]) -> Vec<usize> {
    index_by(activations, |a| {
        (
            a.labels.unit_id.clone(),
            (a.labels.nominal_set_point_celsius() * 1000.0).round() as i64,
        )
    })
}

/// Each activation's index among the distinct values of `key` over all of them, in their order.
fn index_by<K: Ord>(
    activations: &[ActivationSeries],
    key: impl Fn(&ActivationSeries) -> K,
) -> Vec<usize> {
    let mut keys: Vec<K> = activations.iter().map(&key).collect();
    keys.sort();
    keys.dedup();
    activations
        .iter()
        .map(|a| keys.binary_search(&key(a)).unwrap_or(0))
        .collect()
}

/// Scores one candidate on groups of points (one group per activation), cross-validated with
/// `fold[i]` the fold group `i` is held out in: the p-values of the held-out
/// squared residual's and drift's reductions, the coefficient on all data, and whether every
/// fold's coefficient has the same sign.
fn score(groups: &[Vec<Point>], fold_of: &[usize], folds: usize) -> Score {
    let finite = |p: &&Point| p.0.is_finite() && p.1.is_finite();
    let mut signs = (0usize, 0usize);
    let mut improvements = Vec::with_capacity(groups.len());
    let mut drift_gains = Vec::with_capacity(groups.len());
    for fold in 0..folds {
        let train: Vec<&Vec<Point>> = groups
            .iter()
            .enumerate()
            .filter(|(i, _)| fold_of.get(*i) != Some(&fold))
            .map(|(_, g)| g)
            .collect();
        let Some((slope, intercept)) = line(&train) else {
            continue;
        };
        if slope > 0.0 {
            signs.0 += 1;
        } else if slope < 0.0 {
            signs.1 += 1;
        }
        let intercept_only = mean(
            train
                .iter()
                .flat_map(|g| g.iter())
                .filter(finite)
                .map(|p| p.0),
        );
        for group in groups
            .iter()
            .enumerate()
            .filter(|(i, _)| fold_of.get(*i) == Some(&fold))
            .map(|(_, g)| g)
        {
            let (mut without, mut with, mut n) = (0.0, 0.0, 0usize);
            for p in group.iter().filter(finite) {
                without += (p.0 - intercept_only).powi(2);
                with += (p.0 - intercept - slope * p.1).powi(2);
                n += 1;
            }
            if n > 0 {
                improvements.push((without - with) / n as f64);
                let residual = || group.iter().filter(finite);
                drift_gains.push(
                    spread(residual().map(|p| p.0)) - spread(residual().map(|p| p.0 - slope * p.1)),
                );
            }
        }
    }
    let (_, p_value) = one_sided_mean_test(&improvements);
    let (_, drift_p_value) = one_sided_mean_test(&drift_gains);
    let all_groups: Vec<&Vec<Point>> = groups.iter().collect();
    let coefficient = line(&all_groups).map_or(0.0, |(slope, _)| slope);
    Score {
        p_value,
        drift_p_value,
        coefficient,
        stable: signs.0 == 0 || signs.1 == 0,
    }
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n.max(1) as f64
}

/// Each activation's series as an index unique within its stratum (unit, nominal set point): what
/// the shuffles move whole.
fn series_index(activations: &[ActivationSeries]) -> Vec<usize> {
    index_by(activations, |a| {
        (a.labels.series_kind.as_str(), a.labels.series)
    })
}

/// `column` of every activation less its least-squares fit on `baseline`'s columns within
/// activations (pooled coefficients, each activation about its means): what is left of a residual
/// or a candidate once the baseline has explained its part (Frisch–Waugh).
fn partialled(
    activations: &[ActivationSeries],
    axis: usize,
    baseline: &[String],
    column: &dyn Fn(&ActivationSeries) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let values: Vec<Vec<f64>> = activations.iter().map(column).collect();
    if baseline.is_empty() {
        return values;
    }
    let blocks: Vec<crate::gram::Block> = activations
        .iter()
        .zip(&values)
        .map(|(a, y)| {
            let zeros = vec![0.0; y.len()];
            let mut columns: Vec<&[f64]> = baseline
                .iter()
                .filter_map(|n| a.baseline[axis].get(n).map(Vec::as_slice))
                .collect();
            columns.push(&zeros); // no candidate
            columns.push(y);
            crate::gram::Block::of(&columns).centred()
        })
        .collect();
    let Some(beta) = crate::gram::fit_baseline(&blocks) else {
        return values;
    };
    activations
        .iter()
        .zip(values)
        .map(|(a, y)| {
            let mut y = y;
            for (k, n) in baseline.iter().enumerate() {
                if let Some(b) = a.baseline[axis].get(n) {
                    for (v, b) in y.iter_mut().zip(b) {
                        *v -= beta[k] * b;
                    }
                }
            }
            y
        })
        .collect()
}

/// Scores every candidate on one axis of `activations` with `folds`-fold cross-validation by
/// series ([`series_folds`]); `alpha` is the family-wise significance level for the axis, held by
/// the shuffle test ([`crate::permutation`]).
///
/// The statistic is a candidate's **gain over the baseline**: the share of the residual's variance
/// it explains out of sample beyond the baseline's columns (the paper model's ambient gap and the
/// bench's context, [`ActivationSeries::baseline`]). Each candidate is scored at two levels,
/// because effects show in two ways: **within** activations (residual and columns less their
/// activation means: the shape that the drift metric sees, e.g. a temperature-rate term) and
/// **between** activations (one point per activation, the means: offsets that change from one
/// switch-on to the next, e.g. supply voltage or orientation). The better level is reported; the
/// shuffles' winners are the best of both levels of every candidate, so the test covers both.
///
/// Selection is forward, in two steps: first among the unit's own thermal response
/// ([`Kind::is_thermal_response`]), then among every other candidate (the effects) over the
/// baseline and the response selected. In each, the best candidate that is significant
/// (shuffles) and large enough (gain ≥ [`size_threshold`], for an effect
/// [`effect_size_threshold`]) joins the baseline and the rest are scored again over it, up to
/// [`MAX_SELECTED`](crate::selection::MAX_SELECTED) in all. Each candidate's ranking figures are its step's first round;
/// `significant` marks the selected.
///
/// `progress` is asked between shuffles whether to go on ([`Null::measure`](crate::permutation::Null::measure)).
pub fn diagnose_axis(
    activations: &[ActivationSeries],
    axis: usize,
    folds: usize,
    alpha: f64,
    progress: &dyn Progress,
) -> Result<AxisDiagnosis, Interrupted> {
    let names: Vec<String> = activations
        .first()
        .map(|a| a.candidates[axis].keys().cloned().collect())
        .unwrap_or_default();
    let names: Vec<String> = names
        .into_iter()
        .filter(|n| {
            activations
                .iter()
                .all(|a| a.candidates[axis].contains_key(n) && a.left_over[axis].contains_key(n))
        })
        .collect();
    let baseline: Vec<String> = activations
        .first()
        .map(|a| a.baseline[axis].keys().cloned().collect::<Vec<_>>())
        .unwrap_or_default()
        .into_iter()
        .filter(|n| activations.iter().all(|a| a.baseline[axis].contains_key(n)))
        .collect();
    let rms = mean(
        activations
            .iter()
            .flat_map(|a| a.residual_dps[axis].iter().map(|y| y * y)),
    )
    .sqrt();
    let (fold_of, folds) = series_folds(activations, folds);
    let absorbed: BTreeMap<&String, f64> = names
        .iter()
        .map(|n| (n, absorbed_share(activations, axis, n)))
        .collect();
    let remaining: Vec<String> = names
        .iter()
        .filter(|n| absorbed.get(n).is_some_and(|&a| a <= ABSORBED))
        .cloned()
        .collect();
    let residuals: Vec<&[f64]> = activations
        .iter()
        .map(|a| a.residual_dps[axis].as_slice())
        .collect();
    let candidates: Vec<&BTreeMap<String, Vec<f64>>> =
        activations.iter().map(|a| &a.left_over[axis]).collect();
    let strata = set_point_strata(activations);
    let series = series_index(activations);
    let threshold = size_threshold(activations.len());
    let baselines: Vec<&BTreeMap<String, Vec<f64>>> =
        activations.iter().map(|a| &a.baseline[axis]).collect();
    let round = Round {
        axis,
        baseline: &baseline,
        baselines: &baselines,
        residuals: &residuals,
        candidates: &candidates,
        strata: &strata,
        series: &series,
        fold_of: &fold_of,
        folds,
        alpha,
        progress,
    };
    // The unit's own thermal response first, then the effects over it: an effect is what is left
    // once the unit's heating is represented as well as a thermal calibration would.
    let (response, effects): (Vec<String>, Vec<String>) = remaining
        .into_iter()
        .partition(|n| Kind::is_thermal_response(n));
    let mut selected: Vec<Selected> = Vec::new();
    let response_first = round.select(response, &mut selected, threshold, true)?;
    let effect_threshold = effect_size_threshold(activations.len());
    let effect_first = round.select(effects, &mut selected, effect_threshold, false)?;
    // What the baseline alone explains: the first round that was measured.
    let baseline_alone = if response_first.observed.is_empty() {
        &effect_first.baselines
    } else {
        &response_first.baselines
    };
    let first_round = |name: &str| {
        if Kind::is_thermal_response(name) {
            &response_first
        } else {
            &effect_first
        }
    };
    // The per-activation tests and coefficients are read on what the baseline leaves of the
    // residual and of each candidate.
    let residual_left = partialled(activations, axis, &baseline, &|a| {
        a.residual_dps[axis].clone()
    });
    let mut ranking: Vec<CandidateScore> = names
        .iter()
        .map(|name| {
            let absorbed = absorbed.get(name).copied().unwrap_or(1.0);
            let mut candidate = CandidateScore {
                name: name.clone(),
                explained: 0.0,
                p_value: 1.0,
                whole_p_value: 1.0,
                drift_p_value: 1.0,
                significant: false,
                family_p_value: 1.0,
                coefficient: 0.0,
                stable: false,
                absorbed_by_model: absorbed,
                level: "",
                thermal_response: false,
            };
            if absorbed > ABSORBED {
                candidate.level = "absorbed by the model";
                return candidate;
            }
            let finite_mean = |v: &[f64]| mean(v.iter().copied().filter(|x| x.is_finite()));
            let candidate_left = partialled(activations, axis, &baseline, &|a| {
                a.left_over[axis].get(name).cloned().unwrap_or_default()
            });
            let within: Vec<Vec<Point>> = residual_left
                .iter()
                .zip(&candidate_left)
                .map(|(y, c)| {
                    let (my, mc) = (finite_mean(y), finite_mean(c));
                    y.iter().zip(c).map(|(y, c)| (y - my, c - mc)).collect()
                })
                .collect();
            let between: Vec<Vec<Point>> = residual_left
                .iter()
                .zip(&candidate_left)
                .map(|(y, c)| vec![(finite_mean(y), finite_mean(c))])
                .collect();
            let whole: Vec<Vec<Point>> = residual_left
                .iter()
                .zip(&candidate_left)
                .map(|(y, c)| y.iter().copied().zip(c.iter().copied()).collect())
                .collect();
            let within = score(&within, &fold_of, folds);
            let between = score(&between, &fold_of, folds);
            candidate.whole_p_value = score(&whole, &fold_of, folds).p_value;
            // Only a shape has a drift; the between level's one point per activation has none.
            candidate.drift_p_value = within.drift_p_value;
            // The level and gain are the shuffle test's (first round); the p-value and coefficient
            // are read at that level.
            let first = first_round(name);
            let (share, level) = first
                .observed
                .get(name)
                .copied()
                .unwrap_or((0.0, Level::Within));
            let (best, level) = match level {
                Level::Within => (within, WITHIN_ACTIVATIONS),
                Level::Between => (between, BETWEEN_ACTIVATIONS),
            };
            candidate.stable = best.stable;
            candidate.explained = share;
            candidate.family_p_value = first.p_value(share);
            (candidate.p_value, candidate.coefficient, candidate.level) =
                (best.p_value, best.coefficient, level);
            candidate.thermal_response = Kind::is_thermal_response(name);
            if let Some(s) = selected.iter().find(|s| s.name == *name) {
                candidate.significant = true;
                candidate.explained = s.gain;
                candidate.family_p_value = s.family_p_value;
            }
            candidate
        })
        .collect();
    // Selected first, in the order selected, then by gain.
    let order = |c: &CandidateScore| selected.iter().position(|s| s.name == c.name);
    ranking.sort_by(|a, b| match (order(a), order(b)) {
        (Some(x), Some(y)) => x.cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => b.explained.total_cmp(&a.explained),
    });
    Ok(AxisDiagnosis {
        axis: AXES[axis],
        activations: activations.len(),
        residual_rms_dps: rms,
        detectable_share: effect_first.detectable(alpha).max(effect_threshold),
        size_threshold: effect_threshold,
        response_size_threshold: threshold,
        baseline,
        baseline_explained_within: baseline_alone.within_share,
        baseline_explained_between: baseline_alone.between_share,
        selected,
        ranking,
    })
}

/// The step [`diagnose`] reports: axes ranked of 3.
pub const RANKING: &str = "ranking the candidates per axis";

/// Diagnoses all three axes, telling `progress` the axes done ([`RANKING`]) and asking it between
/// shuffles whether to go on.
pub fn diagnose(
    activations: &[ActivationSeries],
    progress: &dyn Progress,
) -> Result<[AxisDiagnosis; 3], Interrupted> {
    let rank = |axis: usize| {
        let done = axis as u64;
        progress.check(RANKING, done, 3)?;
        let within = Within {
            outer: progress,
            step: RANKING,
            done,
            total: 3,
        };
        diagnose_axis(activations, axis, 5, 0.05, &within)
    };
    let axes = [rank(0)?, rank(1)?, rank(2)?];
    progress.check(RANKING, 3, 3)?;
    Ok(axes)
}

#[cfg(test)]
mod tests {
    use super::{score, spread, Point};

    #[test]
    fn the_drift_test_sees_a_shape_and_not_an_unrelated_candidate() {
        // 20 activations whose residual is a ramp of its own size plus a wobble: the ramp as
        // candidate takes the drift down on every held-out activation, the wobble's twin does not.
        let activation = |k: u32, candidate: &dyn Fn(f64) -> f64| -> Vec<Point> {
            let size = 1.0 + f64::from(k % 5);
            (0..50)
                .map(|i| {
                    let t = f64::from(i) / 50.0;
                    let wobble = 0.3 * (7.0 * t + f64::from(k)).sin();
                    (size * t + wobble, candidate(size * t))
                })
                .collect()
        };
        let ramp: Vec<Vec<Point>> = (0..20).map(|k| activation(k, &|ramp| ramp)).collect();
        let folds: Vec<usize> = (0..ramp.len()).map(|i| i % 5).collect();
        let shape = score(&ramp, &folds, 5);
        assert!(
            shape.drift_p_value < 1e-3 && shape.p_value < 1e-3,
            "{}",
            shape.drift_p_value
        );
        let unrelated: Vec<Vec<Point>> = (0..20)
            .map(|k| activation(k, &|ramp| (13.0 * ramp).cos()))
            .collect();
        assert!(score(&unrelated, &folds, 5).drift_p_value > 0.05);
        assert_eq!(spread([1.0, f64::NAN, -2.0]), 3.0);
        assert_eq!(spread([]), 0.0);
    }
}
