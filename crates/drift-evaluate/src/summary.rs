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
}
