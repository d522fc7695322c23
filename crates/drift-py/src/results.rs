//! `gyrodrift.ActivationResult`: one evaluated activation with the data split it was measured
//! on, and the splits' names as `report.json` writes them.

use std::collections::BTreeMap;

use drift_evaluate::evaluate::ActivationResult;
use drift_evaluate::summary::Split;
use pyo3::prelude::*;

use crate::args;
use crate::errors::Error;
use crate::labels::PyLabels;

const SPLITS: [(Split, &str); 4] = [
    (Split::Validation, "validation"),
    (Split::HeldOutRepeat, "held_out_repeat"),
    (Split::Field, "field"),
    (Split::NoiseFloor, "noise_floor"),
];

/// A split's name as in `report.json`.
fn split_name(split: Split) -> &'static str {
    SPLITS
        .iter()
        .find(|(s, _)| *s == split)
        .map_or("validation", |(_, name)| name)
}

/// A split from its `report.json` name.
pub fn split_from(value: &Bound<'_, PyAny>) -> Result<Split, Error> {
    let names: Vec<&str> = SPLITS.iter().map(|(_, n)| *n).collect();
    let text: Option<String> = value.extract().ok();
    SPLITS
        .iter()
        .find(|(_, name)| text.as_deref() == Some(*name))
        .map(|(split, _)| *split)
        .ok_or_else(|| {
            Error::Input(format!(
                "`split` must be one of {}, got {}",
                names.join(", "),
                args::shown(value)
            ))
        })
}

/// Per model name, one value per axis.
type PerModel<T> = BTreeMap<&'static str, (T, T, T)>;

/// One activation corrected with every model, and the data it was measured on.
#[pyclass(module = "gyrodrift", name = "ActivationResult", frozen)]
#[derive(Debug, Clone)]
pub struct PyActivationResult {
    pub split: Split,
    pub result: ActivationResult,
}

impl PyActivationResult {
    fn per_model<T: Copy>(
        &self,
        value: impl Fn(&drift_evaluate::evaluate::ModelResult) -> [T; 3],
    ) -> PerModel<T> {
        self.result
            .models
            .iter()
            .map(|m| {
                let [x, y, z] = value(m);
                (m.model.name(), (x, y, z))
            })
            .collect()
    }
}

#[pymethods]
impl PyActivationResult {
    /// Which data: "validation", "held_out_repeat", "field" or "noise_floor".
    #[getter]
    fn split(&self) -> &'static str {
        split_name(self.split)
    }

    /// The activation's labels.
    #[getter]
    fn labels(&self) -> PyLabels {
        PyLabels(self.result.labels.clone())
    }

    /// Per model ("uncorrected", "standard", "3rd-order", "relative", "relative-cubic", "modified",
    /// "by-history", "recommended"):
    /// drift per axis, °/s (max − min of the 1-s low-frequency rate over the activation).
    #[getter]
    fn drift_dps(&self) -> PerModel<f64> {
        self.per_model(|m| m.drift_dps)
    }

    /// Per model: RMS of the low-frequency rate per axis, °/s (includes the initial-bias error).
    #[getter]
    fn residual_rms_dps(&self) -> PerModel<f64> {
        self.per_model(|m| m.residual_rms_dps)
    }

    /// Per model: union of the corrector's flags over the activation, per axis.
    #[getter]
    fn flags(&self) -> PerModel<u16> {
        self.per_model(|m| m.flags)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let l = &self.result.labels;
        format!(
            "<ActivationResult {} {} {:+} °C series {} repeat {} activation {}>",
            split_name(self.split),
            l.unit_id,
            l.set_point_celsius,
            l.series,
            l.repeat,
            l.activation
        )
    }
}
