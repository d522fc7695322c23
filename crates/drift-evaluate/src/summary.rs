//! The report's table as data: mean drift per unit × set point × split × model × axis.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::evaluate::{ActivationResult, ModelKind};

/// Which data a result was measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Split {
    /// The validation set point(s), never used in the fit.
    Validation,
    /// One repeat at a calibration set point, left out of a refit (leave-one-repeat-out).
    HeldOutRepeat,
    /// Field-like activations (random off-times, ambient ramps, ...), never used in the fit.
    Field,
    /// The zero-systematic-drift unit: the physical limit of the metric.
    NoiseFloor,
}

impl Split {
    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Validation => "validation",
            Self::HeldOutRepeat => "held-out repeat",
            Self::Field => "field",
            Self::NoiseFloor => "noise floor",
        }
    }
}

/// One row of the table as data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Unit id.
    pub unit: String,
    /// The set point the activations belong to, °C: their recording's nominal one
    /// ([`drift_recording::SegmentLabels::nominal_set_point_celsius`]), not the ambient at
    /// switch-on, which differs in field sessions whose ambient ramps.
    pub set_point_celsius: f64,
    /// Which data.
    pub split: Split,
    /// Which model (`uncorrected`, `standard`, `3rd-order`, `modified`).
    pub model: &'static str,
    /// Axis: `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Mean over activations of the drift (max − min of the low-frequency component), °/s.
    pub drift_dps: f64,
    /// Mean over activations of the residual RMS, °/s.
    pub residual_rms_dps: f64,
    /// How many activations.
    pub activations: usize,
}

/// Averages activation results into records, one per unit × set point × split × model × axis;
/// the set point is each activation's nominal one (a ramped field session gives one row, not one
/// per ambient at switch-on).
pub fn summarise(results: &[(Split, ActivationResult)]) -> Vec<Record> {
    type Key = (String, i64, Split, ModelKind, usize);
    let mut sums: BTreeMap<Key, (f64, f64, usize)> = BTreeMap::new();
    for (split, result) in results {
        let set_point = (result.labels.nominal_set_point_celsius() * 1000.0).round() as i64;
        for model in &result.models {
            for axis in 0..3 {
                let entry = sums
                    .entry((
                        result.labels.unit_id.clone(),
                        set_point,
                        *split,
                        model.model,
                        axis,
                    ))
                    .or_default();
                entry.0 += model.drift_dps[axis];
                entry.1 += model.residual_rms_dps[axis];
                entry.2 += 1;
            }
        }
    }
    sums.into_iter()
        .map(
            |((unit, set_point, split, model, axis), (drift, rms, n))| Record {
                unit,
                set_point_celsius: set_point as f64 / 1000.0,
                split,
                model: model.name(),
                axis: ["X", "Y", "Z"][axis],
                drift_dps: drift / n as f64,
                residual_rms_dps: rms / n as f64,
                activations: n,
            },
        )
        .collect()
}

/// How an activation started, for the absolute error: the offset a model leaves depends on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ActivationClass {
    /// A protocol activation after a full cool-down (off at least the calibration's cool-down,
    /// or the first of its series).
    ColdStart,
    /// A protocol activation after a shorter off-time: residual heat at switch-on.
    WarmRestart,
    /// A field-like activation (random off-times, ambient ramps, ...).
    Field,
}

impl ActivationClass {
    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::ColdStart => "cold start",
            Self::WarmRestart => "warm restart",
            Self::Field => "field",
        }
    }

    /// The class of an activation of `split`: warm when it was off less than
    /// `independent_after_min` minutes (the fit's cool-down).
    pub fn of(
        split: Split,
        labels: &drift_recording::SegmentLabels,
        independent_after_min: f64,
    ) -> Self {
        if split == Split::Field {
            return Self::Field;
        }
        match labels.off_before_s {
            Some(s) if s < independent_after_min * 60.0 => Self::WarmRestart,
            _ => Self::ColdStart,
        }
    }
}

/// A model's residual bias RMS over a cell's activations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BiasRms {
    /// Which model.
    pub model: &'static str,
    /// Mean over the cell's activations of the residual bias RMS, °/s.
    pub mean_dps: f64,
    /// The largest over them, °/s.
    pub worst_dps: f64,
    /// The activation it was measured on (`series S, repeat R, activation A`).
    pub worst_activation: String,
    /// How many of the cell's activations this model switched on outside its calibrated envelope
    /// (clamped: ambient or temperature out of range).
    pub outside_envelope: usize,
}

/// The absolute error of one unit × axis × set point × activation class on held-out data: the
/// residual bias RMS of the paper's model and of every standard baseline, the best baseline, and
/// the noise floor beside them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AbsoluteCell {
    /// Unit id.
    pub unit: String,
    /// Axis: `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Nominal set point, °C.
    pub set_point_celsius: f64,
    /// How the activations started.
    pub class: ActivationClass,
    /// How many activations.
    pub activations: usize,
    /// The paper's model (`modified`).
    pub modified: BiasRms,
    /// The paper's curves keyed by history, started from what firmware kept (`by-history`).
    pub by_history: BiasRms,
    /// The recommended model, started from what firmware kept (`recommended`).
    pub recommended: BiasRms,
    /// The recommended model's mean over the best baseline's (the floor it is held to: ≤ 1).
    pub recommended_ratio: f64,
    /// Every standard baseline, in report order.
    pub baselines: Vec<BiasRms>,
    /// The baseline with the smallest mean.
    pub best_baseline: &'static str,
    /// The paper's model's mean over the best baseline's.
    pub ratio: f64,
    /// Whether the paper's model is worse than [`WORSE_THAN_BASELINE`] × the best baseline.
    pub worse: bool,
    /// Mean residual bias RMS the paper's model leaves on the zero-drift unit's activations of
    /// this class (turn-on repeatability and noise: what no model can remove), °/s; NaN without a
    /// noise-floor unit.
    pub noise_floor_dps: f64,
}

/// The paper's model is flagged where its residual bias RMS exceeds the best baseline's by more
/// than this factor.
pub const WORSE_THAN_BASELINE: f64 = 1.25;

fn activation_name(labels: &drift_recording::SegmentLabels) -> String {
    format!(
        "series {}, repeat {}, activation {}",
        labels.series, labels.repeat, labels.activation
    )
}

/// A cell of the absolute-error table: unit, nominal set point (m°C), activation class, axis.
pub type CellKey = (String, i64, ActivationClass, usize);

/// Every held-out activation of `results` (not the noise floor's) by unit × set point × class ×
/// axis: the cells of [`absolute_error`].
pub fn cells(
    results: &[(Split, ActivationResult)],
    independent_after_min: f64,
) -> BTreeMap<CellKey, Vec<&ActivationResult>> {
    let mut cells: BTreeMap<CellKey, Vec<&ActivationResult>> = BTreeMap::new();
    for (split, result) in results.iter().filter(|(s, _)| *s != Split::NoiseFloor) {
        let class = ActivationClass::of(*split, &result.labels, independent_after_min);
        let set_point = (result.labels.nominal_set_point_celsius() * 1000.0).round() as i64;
        for axis in 0..3 {
            cells
                .entry((result.labels.unit_id.clone(), set_point, class, axis))
                .or_default()
                .push(result);
        }
    }
    cells
}

/// The absolute error per unit × axis × set point × activation class, on every held-out
/// activation of `results` (validation, held-out repeats, field); the noise floor from the
/// [`Split::NoiseFloor`] results of the same class (any class if that one has none).
pub fn absolute_error(
    results: &[(Split, ActivationResult)],
    independent_after_min: f64,
) -> Vec<AbsoluteCell> {
    let cells = cells(results, independent_after_min);
    let mut floor: BTreeMap<ActivationClass, (f64, usize)> = BTreeMap::new();
    for (split, result) in results.iter().filter(|(s, _)| *s == Split::NoiseFloor) {
        let class = ActivationClass::of(*split, &result.labels, independent_after_min);
        if let Some(m) = result
            .models
            .iter()
            .find(|m| m.model == ModelKind::Modified)
        {
            let entry = floor.entry(class).or_default();
            for rms in m.residual_rms_dps {
                entry.0 += rms;
                entry.1 += 1;
            }
        }
    }
    let any_floor = floor
        .values()
        .fold((0.0, 0), |(s, n), (fs, fn_)| (s + fs, n + fn_));
    let floor_of = |class| {
        let (sum, n) = floor.get(&class).copied().unwrap_or(any_floor);
        if n == 0 {
            f64::NAN
        } else {
            sum / n as f64
        }
    };
    let rms_of = |members: &[&ActivationResult], model: ModelKind, axis: usize| {
        let mut sum = 0.0;
        let mut worst = (f64::NEG_INFINITY, String::new());
        let mut outside = 0;
        let out_flags = drift_core::Flags::AMBIENT_OUT_OF_RANGE.0
            | drift_core::Flags::TEMPERATURE_OUT_OF_RANGE.0;
        for r in members {
            let Some(m) = r.models.iter().find(|m| m.model == model) else {
                continue;
            };
            let v = m.residual_rms_dps[axis];
            sum += v;
            if v > worst.0 {
                worst = (v, activation_name(&r.labels));
            }
            if m.flags[axis] & out_flags != 0 {
                outside += 1;
            }
        }
        BiasRms {
            model: model.name(),
            mean_dps: sum / members.len().max(1) as f64,
            worst_dps: worst.0,
            worst_activation: worst.1,
            outside_envelope: outside,
        }
    };
    cells
        .into_iter()
        .map(|((unit, set_point, class, axis), members)| {
            let modified = rms_of(&members, ModelKind::Modified, axis);
            let by_history = rms_of(&members, ModelKind::ByHistory, axis);
            let recommended = rms_of(&members, ModelKind::Recommended, axis);
            // Only the baselines evaluated: an absent one is not a zero error.
            let baselines: Vec<BiasRms> = ModelKind::BASELINES
                .iter()
                .filter(|&&b| {
                    members
                        .iter()
                        .any(|r| r.models.iter().any(|m| m.model == b))
                })
                .map(|&b| rms_of(&members, b, axis))
                .collect();
            let best = baselines
                .iter()
                .min_by(|a, b| a.mean_dps.total_cmp(&b.mean_dps))
                .map_or(("–", f64::NAN), |b| (b.model, b.mean_dps));
            let ratio = modified.mean_dps / best.1;
            let recommended_ratio = recommended.mean_dps / best.1;
            AbsoluteCell {
                unit,
                axis: ["X", "Y", "Z"][axis],
                set_point_celsius: set_point as f64 / 1000.0,
                class,
                activations: members.len(),
                modified,
                by_history,
                recommended,
                recommended_ratio,
                baselines,
                best_baseline: best.0,
                ratio,
                worse: ratio > WORSE_THAN_BASELINE,
                noise_floor_dps: floor_of(class),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use drift_recording::{SegmentLabels, SeriesKind};

    use super::*;
    use crate::evaluate::ModelResult;

    /// A field activation switched on at `at_switch_on` in a session at `session`, with drift
    /// `drift` on every axis.
    fn result(at_switch_on: f64, session: Option<f64>, drift: f64) -> (Split, ActivationResult) {
        let labels = SegmentLabels {
            unit_id: "U".into(),
            set_point_celsius: at_switch_on,
            session_set_point_celsius: session,
            series_kind: SeriesKind::Field,
            series: 1,
            repeat: 1,
            activation: 1,
            interval_min: None,
            off_before_s: None,
        };
        let models = vec![ModelResult {
            model: ModelKind::Uncorrected,
            drift_dps: [drift; 3],
            residual_rms_dps: [drift; 3],
            flags: [0; 3],
        }];
        (Split::Field, ActivationResult { labels, models })
    }

    #[test]
    fn ramped_activations_are_summarised_under_their_sessions_set_point() {
        let results = [
            result(31.7, Some(33.0), 0.01),
            result(35.2, Some(33.0), 0.03),
            result(33.0, None, 0.02),
            // No session set point recorded: the switch-on one.
            result(36.5, None, 0.04),
        ];
        let rows: Vec<(f64, usize, f64)> = summarise(&results)
            .iter()
            .filter(|r| r.axis == "X")
            .map(|r| (r.set_point_celsius, r.activations, r.drift_dps))
            .collect();
        assert_eq!(rows.len(), 2, "{rows:?}");
        assert_eq!((rows[0].0, rows[0].1), (33.0, 3));
        assert!((rows[0].2 - 0.02).abs() < 1e-12, "{rows:?}");
        assert_eq!((rows[1].0, rows[1].1), (36.5, 1));
    }

    /// A protocol activation after `off_before_s`, with the given residual RMS per model on X.
    fn protocol(
        off_before_s: f64,
        activation: u32,
        rms: &[(ModelKind, f64)],
    ) -> (Split, ActivationResult) {
        let labels = SegmentLabels {
            unit_id: "U".into(),
            set_point_celsius: 40.0,
            session_set_point_celsius: None,
            series_kind: SeriesKind::Protocol,
            series: 1,
            repeat: 2,
            activation,
            interval_min: None,
            off_before_s: Some(off_before_s),
        };
        let models = rms
            .iter()
            .map(|&(model, v)| ModelResult {
                model,
                drift_dps: [0.001; 3],
                residual_rms_dps: [v, 0.001, 0.001],
                flags: [
                    if model == ModelKind::Modified && off_before_s < 900.0 {
                        drift_core::Flags::AMBIENT_OUT_OF_RANGE.0
                    } else {
                        0
                    },
                    0,
                    0,
                ],
            })
            .collect();
        (Split::HeldOutRepeat, ActivationResult { labels, models })
    }

    #[test]
    fn the_absolute_error_flags_a_class_where_the_model_is_worse_than_the_best_baseline() {
        use ModelKind::*;
        let results = [
            protocol(
                3600.0,
                1,
                &[
                    (Standard, 0.010),
                    (ThirdOrder, 0.004),
                    (Relative, 0.005),
                    (Modified, 0.004),
                ],
            ),
            protocol(
                60.0,
                2,
                &[
                    (Standard, 0.010),
                    (ThirdOrder, 0.004),
                    (Relative, 0.006),
                    (Modified, 0.020),
                ],
            ),
            protocol(
                60.0,
                3,
                &[
                    (Standard, 0.010),
                    (ThirdOrder, 0.006),
                    (Relative, 0.004),
                    (Modified, 0.030),
                ],
            ),
        ];
        let cells = absolute_error(&results, 15.0);
        let x: Vec<&AbsoluteCell> = cells.iter().filter(|c| c.axis == "X").collect();
        assert_eq!(x.len(), 2, "{cells:?}");
        let (cold, warm) = (x[0], x[1]);
        assert_eq!(
            (cold.class, cold.activations, cold.worse),
            (ActivationClass::ColdStart, 1, false)
        );
        assert_eq!(
            (warm.class, warm.activations),
            (ActivationClass::WarmRestart, 2)
        );
        // Best baseline on the warm restarts: 3rd-order and relative both average 0.005; the
        // first in report order wins the tie.
        assert_eq!(warm.best_baseline, "3rd-order");
        assert!(warm.worse && (warm.ratio - 5.0).abs() < 1e-9, "{warm:?}");
        assert_eq!(warm.modified.worst_dps, 0.030);
        assert_eq!(
            warm.modified.worst_activation,
            "series 1, repeat 2, activation 3"
        );
        assert_eq!(warm.modified.outside_envelope, 2);
        assert!(warm.noise_floor_dps.is_nan());
    }
}
