//! Diagnosis: after correction by the paper's model, is a systematic effect left in the residual,
//! and which recorded or derived quantity explains it?
//!
//! For every evaluated activation, the corrected rate's low-frequency residual is put on a coarse
//! grid beside candidate explanations: every auxiliary channel the recording has (whatever its
//! name) and derived quantities (temperature rate per axis, rise², the other axes' rises, time since
//! switch-on, switch-on temperature, residual heat at switch-on, campaign time). Before scoring, each
//! candidate is stripped of what the paper's model already accounts for: it is replaced by its
//! residual after a least-squares fit on the model's own inputs (time since switch-on, rise, the
//! model's drift estimate, ambient), within the training folds. A candidate the table explains is
//! then left with nothing to explain.
//!
//! Score: out-of-sample explained variance of the residual, cross-validated by activation
//! (K folds of whole activations, never samples), for a one-coefficient linear term. Significance:
//! per-activation reductions of squared error on held-out activations, one-sided t-test of their
//! mean against zero, Bonferroni-corrected over every candidate of the axis. Activations are the
//! independent samples; the noise inside one is strongly autocorrelated.

use std::collections::BTreeMap;

use drift_core::Model;
use drift_recording::{Segment, SegmentLabels};
use serde::Serialize;

use crate::evaluate::{correct_segment, switch_on_raw};
use crate::fit::FittedUnit;
use crate::lowpass::centred_moving_average;
use crate::settings::FitSettings;

/// Spacing of the diagnosis grid, ms: the residual is low-passed at 1 s, so 10 Hz keeps it whole.
pub const GRID_MS: u32 = 100;
const AXES: [&str; 3] = ["X", "Y", "Z"];

/// One activation on the diagnosis grid.
#[derive(Debug, Clone)]
pub struct ActivationSeries {
    /// Labels.
    pub labels: SegmentLabels,
    /// Low-frequency residual after the paper's model, per axis, °/s.
    pub residual_dps: [Vec<f64>; 3],
    /// The model's own inputs per axis (what candidates are stripped of): time, rise, drift
    /// estimate, ambient.
    pub model_inputs: [Vec<[f64; 4]>; 3],
    /// Candidates per axis, by name.
    pub candidates: [BTreeMap<String, Vec<f64>>; 3],
}

fn grid_step(segment: &Segment) -> usize {
    (segment.sample_rate_hz as usize * GRID_MS as usize / 1000).max(1)
}

/// Low-pass at the fit's window and sample on the diagnosis grid.
fn on_grid<T: Copy + Into<f64>>(values: &[T], window: usize, step: usize) -> Vec<f64> {
    centred_moving_average(values, window)
        .into_iter()
        .step_by(step)
        .collect()
}

/// Puts one activation, corrected by `fitted`'s paper model, on the diagnosis grid.
pub fn series(fitted: &FittedUnit, segment: &Segment, settings: &FitSettings) -> ActivationSeries {
    let window = settings.lowpass_window_samples;
    let step = grid_step(segment);
    let switch_on = switch_on_raw(segment, settings);
    let (corrected, _) = correct_segment(&fitted.modified, segment, switch_on);
    let settings_core = fitted.modified.settings();
    let n = segment.len().div_ceil(step);
    let time: Vec<f64> = (0..n)
        .map(|i| (i * step) as f64 / f64::from(segment.sample_rate_hz))
        .collect();
    let celsius: [Vec<f64>; 3] = [0, 1, 2].map(|a| {
        on_grid(&segment.temperature_raw[a], window, step)
            .into_iter()
            .map(|r| f64::from(settings_core.celsius(r as f32)))
            .collect()
    });
    let on_celsius: [f64; 3] = switch_on.map(|r| f64::from(settings_core.celsius(r)));
    let rise: [Vec<f64>; 3] =
        [0, 1, 2].map(|a| celsius[a].iter().map(|c| c - on_celsius[a]).collect());
    let residual: [Vec<f64>; 3] = [0, 1, 2].map(|a| on_grid(&corrected[a], window, step));
    let raw_rate: [Vec<f64>; 3] = [0, 1, 2].map(|a| on_grid(&segment.rate_dps[a], window, step));
    // Shared candidates: auxiliary channels (resampled to the grid), time, campaign time.
    let mut shared: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for (name, channel) in &segment.aux {
        let aux_step = ((channel.sample_rate_hz as usize * GRID_MS as usize) / 1000).max(1);
        let aux_window = (channel.sample_rate_hz as usize).max(1); // 1 s, like the residual
        let mut values = on_grid(&channel.values, aux_window, aux_step);
        values.resize(n, values.last().copied().unwrap_or(0.0));
        shared.insert(format!("aux:{name}"), values);
    }
    shared.insert("time since switch-on".into(), time.clone());
    let campaign_s = segment.power_on_ns as f64 / 1e9;
    shared.insert(
        "campaign time (ageing)".into(),
        time.iter().map(|t| campaign_s + t).collect(),
    );
    let set_point = segment
        .aux
        .get("chamber_set_point")
        .and_then(|c| c.values.first())
        .map(|&v| f64::from(v));
    let candidates = [0, 1, 2].map(|a| {
        let mut own = shared.clone();
        // Temperature rate, °C/s, from the low-passed temperature (central difference over ±1 s).
        let half = (1000 / GRID_MS) as usize;
        let rate: Vec<f64> = (0..n)
            .map(|i| {
                let (lo, hi) = (i.saturating_sub(half), (i + half).min(n - 1));
                if hi > lo {
                    (celsius[a][hi] - celsius[a][lo]) / (time[hi] - time[lo])
                } else {
                    0.0
                }
            })
            .collect();
        own.insert(format!("temperature rate {}", AXES[a]), rate);
        own.insert(
            format!("rise² {}", AXES[a]),
            rise[a].iter().map(|r| r * r).collect(),
        );
        for b in (0..3).filter(|&b| b != a) {
            own.insert(format!("rise {}", AXES[b]), rise[b].clone());
        }
        own.insert("switch-on temperature".into(), vec![on_celsius[a]; n]);
        if let Some(set_point) = set_point {
            own.insert(
                "residual heat at switch-on (off-time)".into(),
                vec![on_celsius[a] - set_point; n],
            );
        }
        own
    });
    let model_inputs = [0, 1, 2].map(|a| {
        (0..n)
            .map(|i| {
                // The model's drift estimate is what it subtracted beyond the initial bias.
                let estimate = raw_rate[a][i] - residual[a][i];
                [time[i], rise[a][i], estimate, on_celsius[a]]
            })
            .collect()
    });
    ActivationSeries {
        labels: segment.labels.clone(),
        residual_dps: residual,
        model_inputs,
        candidates,
    }
}

/// One candidate's score on one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateScore {
    /// Candidate name.
    pub name: String,
    /// Out-of-sample share of the residual's variance explained (cross-validated by activation).
    pub explained: f64,
    /// One-sided p-value of the mean held-out improvement (before multiple-comparison correction).
    pub p_value: f64,
    /// Whether it passes the Bonferroni-corrected test at `alpha`.
    pub significant: bool,
    /// Fitted coefficient on all data ((°/s) per candidate unit, after stripping).
    pub coefficient: f64,
    /// Share of the candidate's own variance that the paper's model inputs already explain. Near 1:
    /// the table accounts for this quantity, and it is not scored.
    pub absorbed_by_model: f64,
    /// Where the effect shows: within activations (shape), between activations (offsets), or
    /// absorbed by the model.
    pub level: &'static str,
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
    /// Candidates, best first.
    pub ranking: Vec<CandidateScore>,
}

impl AxisDiagnosis {
    /// The winning candidate, if any is significant.
    pub fn chosen(&self) -> Option<&CandidateScore> {
        self.ranking.first().filter(|c| c.significant)
    }
}

/// A candidate whose variance the model inputs explain beyond this share is the table's already.
const ABSORBED: f64 = 0.999;

fn model_row(a: &ActivationSeries, axis: usize, i: usize) -> Vec<f64> {
    let m = a.model_inputs[axis][i];
    vec![1.0, m[0], m[1], m[2], m[3]]
}

/// R² of the candidate regressed on the model's inputs, over all activations.
fn absorbed_share(activations: &[ActivationSeries], axis: usize, name: &str) -> f64 {
    let (rows, values): (Vec<Vec<f64>>, Vec<f64>) = activations
        .iter()
        .flat_map(|a| {
            (0..a.residual_dps[axis].len())
                .map(move |i| (model_row(a, axis, i), a.candidates[axis][name][i]))
        })
        .unzip();
    let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
    let total: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
    if total <= 0.0 {
        return 1.0; // a constant: nothing left once the intercept is taken out
    }
    let b = least_squares(&rows, &values);
    let left: f64 = rows
        .iter()
        .zip(&values)
        .map(|(r, v)| (v - r.iter().zip(&b).map(|(x, c)| x * c).sum::<f64>()).powi(2))
        .sum();
    1.0 - left / total
}

/// Least squares `y ≈ X b` via normal equations (columns ≤ 6).
pub(crate) fn least_squares(rows: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let k = rows.first().map_or(0, Vec::len);
    if k == 0 {
        return Vec::new();
    }
    let mut normal = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut rhs = nalgebra::DVector::<f64>::zeros(k);
    // A non-finite point (a sensor fault the corrector flagged) says nothing about the effect, and
    // one NaN would poison the whole solve: it is left out.
    let finite = |row: &Vec<f64>, t: f64| t.is_finite() && row.iter().all(|v| v.is_finite());
    for (row, &t) in rows.iter().zip(y).filter(|(row, t)| finite(row, **t)) {
        for r in 0..k {
            rhs[r] += row[r] * t;
            for c in 0..k {
                normal[(r, c)] += row[r] * row[c];
            }
        }
    }
    // A tiny ridge keeps constant or collinear candidates solvable (their stripped part is ~0).
    for d in 0..k {
        normal[(d, d)] += 1e-12 * (1.0 + normal[(d, d)]);
    }
    normal
        .lu()
        .solve(&rhs)
        .map_or_else(|| vec![0.0; k], |b| b.iter().copied().collect())
}

fn standard_normal_tail(z: f64) -> f64 {
    // Upper tail of N(0,1) via the complementary error function (Abramowitz–Stegun 7.1.26).
    let t = 1.0 / (1.0 + 0.3275911 * z.abs() / std::f64::consts::SQRT_2);
    let poly = t
        * (0.254829592
            + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    let erfc = poly * (-(z * z) / 2.0).exp();
    if z >= 0.0 {
        0.5 * erfc
    } else {
        1.0 - 0.5 * erfc
    }
}

/// One point of the scoring data: residual, candidate, the model-input row it is stripped against.
type Point = (f64, f64, [f64; 5]);

/// Scores one candidate on groups of points (one group per activation): cross-validated by group,
/// stripped within the training folds. Returns (explained share, one-sided p, coefficient).
fn score(groups: &[Vec<Point>], folds: usize) -> (f64, f64, f64) {
    let all: Vec<&Point> = groups.iter().flatten().collect();
    let mean_y = all.iter().map(|p| p.0).sum::<f64>() / all.len().max(1) as f64;
    let total: f64 = all.iter().map(|p| (p.0 - mean_y).powi(2)).sum();
    let folds = folds.clamp(2, groups.len().max(2));
    let fit = |train: &[&Vec<Point>]| {
        let (rows, values): (Vec<Vec<f64>>, Vec<f64>) = train
            .iter()
            .flat_map(|g| g.iter().map(|p| (p.2.to_vec(), p.1)))
            .unzip();
        let strip = least_squares(&rows, &values);
        let stripped =
            move |p: &Point| p.1 - p.2.iter().zip(&strip).map(|(x, b)| x * b).sum::<f64>();
        let (rows, ys): (Vec<Vec<f64>>, Vec<f64>) = train
            .iter()
            .flat_map(|g| g.iter().map(|p| (vec![1.0, stripped(p)], p.0)))
            .unzip();
        let beta = least_squares(&rows, &ys);
        let intercept_only = ys.iter().sum::<f64>() / ys.len().max(1) as f64;
        (stripped, beta, intercept_only)
    };
    let mut improvements = Vec::with_capacity(groups.len());
    let mut sse = 0.0;
    for fold in 0..folds {
        let train: Vec<&Vec<Point>> = groups
            .iter()
            .enumerate()
            .filter(|(i, _)| i % folds != fold)
            .map(|(_, g)| g)
            .collect();
        let (stripped, beta, intercept_only) = fit(&train);
        for group in groups
            .iter()
            .enumerate()
            .filter(|(i, _)| i % folds == fold)
            .map(|(_, g)| g)
        {
            let (mut without, mut with) = (0.0, 0.0);
            for p in group {
                without += (p.0 - intercept_only).powi(2);
                with += (p.0 - beta[0] - beta[1] * stripped(p)).powi(2);
            }
            sse += with;
            improvements.push((without - with) / group.len().max(1) as f64);
        }
    }
    let n = improvements.len() as f64;
    let mean = improvements.iter().sum::<f64>() / n.max(1.0);
    let sd =
        (improvements.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    let z = if sd > 0.0 {
        mean / (sd / n.sqrt())
    } else {
        0.0
    };
    let all_groups: Vec<&Vec<Point>> = groups.iter().collect();
    let (_, beta, _) = fit(&all_groups);
    let explained = if total > 0.0 { 1.0 - sse / total } else { 0.0 };
    (
        explained,
        standard_normal_tail(z),
        beta.get(1).copied().unwrap_or(0.0),
    )
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n.max(1) as f64
}

/// Scores every candidate on one axis of `activations` with `folds`-fold cross-validation by
/// activation; `alpha` is the family-wise significance level for the axis.
///
/// Each candidate is scored at two levels, because effects show in two ways: **within**
/// activations (residual and candidate less their activation means: the shape that the drift
/// metric sees, e.g. a temperature-rate term) and **between** activations (one point per activation,
/// the means: offsets that change from one switch-on to the next, e.g. supply voltage or
/// orientation). The better level is reported; Bonferroni covers both levels of every candidate.
pub fn diagnose_axis(
    activations: &[ActivationSeries],
    axis: usize,
    folds: usize,
    alpha: f64,
) -> AxisDiagnosis {
    let names: Vec<String> = activations
        .first()
        .map(|a| a.candidates[axis].keys().cloned().collect())
        .unwrap_or_default();
    let names: Vec<String> = names
        .into_iter()
        .filter(|n| {
            activations
                .iter()
                .all(|a| a.candidates[axis].contains_key(n))
        })
        .collect();
    let rms = mean(
        activations
            .iter()
            .flat_map(|a| a.residual_dps[axis].iter().map(|y| y * y)),
    )
    .sqrt();
    let row = |a: &ActivationSeries, i: usize| {
        let m = a.model_inputs[axis][i];
        [1.0, m[0], m[1], m[2], m[3]]
    };
    let mut ranking: Vec<CandidateScore> = names
        .iter()
        .map(|name| {
            let absorbed = absorbed_share(activations, axis, name);
            let mut candidate = CandidateScore {
                name: name.clone(),
                explained: 0.0,
                p_value: 1.0,
                significant: false,
                coefficient: 0.0,
                absorbed_by_model: absorbed,
                level: "",
            };
            if absorbed > ABSORBED {
                candidate.level = "absorbed by the model";
                return candidate;
            }
            let within: Vec<Vec<Point>> = activations
                .iter()
                .map(|a| {
                    let n = a.residual_dps[axis].len();
                    let c = &a.candidates[axis][name];
                    let (my, mc) = (
                        mean(a.residual_dps[axis].iter().copied()),
                        mean(c.iter().copied()),
                    );
                    let mrow: [f64; 5] =
                        std::array::from_fn(|k| mean((0..n).map(|i| row(a, i)[k])));
                    (0..n)
                        .map(|i| {
                            (
                                a.residual_dps[axis][i] - my,
                                c[i] - mc,
                                std::array::from_fn(|k| row(a, i)[k] - mrow[k]),
                            )
                        })
                        .collect()
                })
                .collect();
            let between: Vec<Vec<Point>> = activations
                .iter()
                .map(|a| {
                    let n = a.residual_dps[axis].len();
                    let c = &a.candidates[axis][name];
                    vec![(
                        mean(a.residual_dps[axis].iter().copied()),
                        mean(c.iter().copied()),
                        std::array::from_fn(|k| mean((0..n).map(|i| row(a, i)[k]))),
                    )]
                })
                .collect();
            let (we, wp, wc) = score(&within, folds);
            let (be, bp, bc) = score(&between, folds);
            (
                candidate.explained,
                candidate.p_value,
                candidate.coefficient,
                candidate.level,
            ) = if wp <= bp {
                (we, wp, wc, "within activations")
            } else {
                (be, bp, bc, "between activations")
            };
            candidate
        })
        .collect();
    let bonferroni = alpha / (2 * ranking.len()).max(1) as f64;
    for c in &mut ranking {
        c.significant = c.p_value < bonferroni && c.explained > 0.0;
    }
    // Significant first, then by explained share.
    ranking.sort_by(|a, b| {
        b.significant
            .cmp(&a.significant)
            .then(b.explained.total_cmp(&a.explained))
    });
    AxisDiagnosis {
        axis: AXES[axis],
        activations: activations.len(),
        residual_rms_dps: rms,
        ranking,
    }
}

/// Diagnoses all three axes.
pub fn diagnose(activations: &[ActivationSeries]) -> [AxisDiagnosis; 3] {
    [0, 1, 2].map(|axis| diagnose_axis(activations, axis, 5, 0.05))
}

#[cfg(test)]
mod tests {
    use super::least_squares;

    #[test]
    fn least_squares_leaves_out_non_finite_points() {
        // y = 2 + 3x, one NaN residual and one infinite candidate among them.
        let mut rows: Vec<Vec<f64>> = (0..10).map(|i| vec![1.0, f64::from(i)]).collect();
        let mut y: Vec<f64> = (0..10).map(|i| 2.0 + 3.0 * f64::from(i)).collect();
        y[3] = f64::NAN;
        rows[5][1] = f64::INFINITY;
        let b = least_squares(&rows, &y);
        assert!(
            (b[0] - 2.0).abs() < 1e-6 && (b[1] - 3.0).abs() < 1e-6,
            "{b:?}"
        );
        assert!(least_squares(&[], &[]).is_empty());
    }
}
