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
