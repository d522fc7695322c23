//! `ModifiedTables.check` / `PolynomialTables.check`: the command line's `gyrodrift check` for one
//! unit's model, on recordings or segments, as records (drift-fit's `check` does the work).

use std::sync::Arc;

use drift_core::Model;
use drift_evaluate::check::{Limits, UnitCheck};
use drift_fit::FitSettings;
use drift_recording::{read_recording, Segment};
use pyo3::prelude::*;

use crate::errors::Error;
use crate::fit_settings;
use crate::sources::{self, Source};

/// The limits from the keyword arguments (drift-fit says which are valid).
pub fn limits(max_drift: f64, max_rms: f64, min_removed: f64) -> Result<Limits, Error> {
    let limits = Limits {
        max_drift_dps: max_drift,
        max_residual_rms_dps: max_rms,
        min_removed,
    };
    match limits.invalid() {
        None => Ok(limits),
        Some((field, value)) => {
            let argument = match field {
                "max_drift_dps" => "max_drift",
                "max_residual_rms_dps" => "max_rms",
                _ => "min_removed",
            };
            Err(Error::Input(format!(
                "`{argument}` must be {}, got {value}",
                Limits::requirement(field)
            )))
        }
    }
}

/// Corrects every activation of `source` (one unit's) with `model`; one record per axis.
pub fn check<'py, M: Model + Clone + Send + Sync>(
    py: Python<'py>,
    model: &Arc<M>,
    source: &Bound<'py, PyAny>,
    limits: &Limits,
    settings: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let settings: FitSettings = fit_settings::or_default(settings)?;
    let source = sources::source(py, "source", source)?;
    let model = Arc::clone(model);
    let records = py.detach(|| -> Result<String, Error> {
        let mut unit: Option<UnitCheck<M>> = None;
        let mut add = |segment: &Segment| -> Result<(), Error> {
            let id = &segment.labels.unit_id;
            let check = match &mut unit {
                Some(check) => check,
                None => unit.insert(
                    UnitCheck::new(id, (*model).clone(), &settings)
                        .map_err(|e| Error::Input(e.to_string()))?,
                ),
            };
            if check.unit_id() != id {
                return Err(Error::Input(format!(
                    "`source` must hold one unit's activations (a model is one unit's), got `{}` and `{id}`",
                    check.unit_id()
                )));
            }
            check.add(segment);
            Ok(())
        };
        match &source {
            Source::Files(files) => {
                for path in files {
                    for segment in &read_recording(path)?.segments {
                        add(segment)?;
                    }
                }
            }
            Source::Segments(segments) => {
                for segment in segments {
                    add(segment)?;
                }
            }
        }
        let Some(unit) = unit else {
            return Err(Error::Input(
                "`source` holds no activations to check".to_owned(),
            ));
        };
        let records: Vec<serde_json::Value> = unit
            .verdicts(limits)
            .iter()
            .map(|v| {
                let axis = ["X", "Y", "Z"].get(v.axis).copied().unwrap_or("?");
                serde_json::json!({
                    "unit_id": unit.unit_id(),
                    "axis": axis,
                    "passed": v.passed(),
                    "activations": v.activations,
                    "uncorrected_drift_dps": v.uncorrected_drift_dps,
                    "corrected_drift_dps": v.corrected_drift_dps,
                    "worst_drift_dps": v.worst_drift_dps,
                    "removed": v.removed,
                    "residual_rms_dps": v.residual_rms_dps,
                    "ambient_out_of_range": v.ambient_out_of_range,
                    "rise_out_of_span": v.rise_out_of_span,
                    "past_last_reference": v.past_last_reference,
                    "history_unknown_or_out_of_span": v.history_unknown_or_out_of_span,
                    "outside_envelope": v.outside_envelope,
                    "samples": v.samples,
                    "outside_envelope_samples": v.outside_envelope_samples,
                    "faulty": v.faulty,
                    "failures": v.failures,
                })
            })
            .collect();
        serde_json::to_string(&records)
            .map_err(|e| Error::Input(format!("internal: check records JSON: {e}")))
    })?;
    py.import("json")?.call_method1("loads", (records,))
}
