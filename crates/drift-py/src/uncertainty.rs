//! `gyrodrift.Uncertainty`: σ(t), the residual bias's standard deviation after switch-on, as
//! drift-core computes it beside each corrected sample.

use std::path::PathBuf;

use drift_core::blob::decode_section;
use drift_core::{Previous, SwitchOn, Uncertainty};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

use crate::args::per_axis;
use crate::arrays::times;
use crate::corrector::previous_arg;
use crate::errors::Error;
use crate::model_io;

/// σ(t) of one unit: per class (cold start, warm restart) a piecewise-linear curve of time since
/// switch-on, plus a growth per °C of switch-on ambient outside the calibrated envelope.
#[pyclass(module = "gyrodrift", name = "Uncertainty", eq)]
#[derive(Debug, Clone, PartialEq)]
pub struct PyUncertainty {
    inner: Uncertainty,
}

fn invalid(path: &std::path::Path, e: impl std::fmt::Display) -> Error {
    Error::Input(format!("{}: {e}", path.display()))
}

#[pymethods]
impl PyUncertainty {
    /// Reads `uncertainty.json` (drift-core's serde form) or `uncertainty.bin` (the firmware's
    /// σ(t) section) of a tables folder; the error names the file and what is wrong.
    #[staticmethod]
    fn load(path: PathBuf) -> Result<Self, Error> {
        let inner = if path.extension().is_some_and(|e| e == "json") {
            let text = model_io::read_text(&path)?;
            let inner: Uncertainty = serde_json::from_str(&text).map_err(|e| invalid(&path, e))?;
            inner.validate().map_err(|e| invalid(&path, e))?;
            inner
        } else {
            decode_section(&model_io::read(&path)?).map_err(|e| invalid(&path, e))?
        };
        Ok(Self { inner })
    }

    /// Knot times since switch-on, ms.
    #[getter]
    fn knots_ms(&self) -> Vec<u32> {
        self.inner.knots_ms.to_vec()
    }

    /// σ at the knots, °/s: `(2, knots)`, cold start then warm restart.
    #[getter]
    fn sigma_dps<'py>(&self, py: Python<'py>) -> Result<Bound<'py, PyArray2<f32>>, Error> {
        let rows: Vec<f32> = self.inner.sigma_dps.iter().flatten().copied().collect();
        let shape = (self.inner.sigma_dps.len(), self.inner.knots_ms.len());
        Array2::from_shape_vec(shape, rows)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| Error::Input(format!("internal: sigma shape: {e}")))
    }

    /// Residual heat at switch-on above which a start is a warm restart, °C.
    #[getter]
    fn warm_above_celsius(&self) -> f32 {
        self.inner.warm_above_celsius
    }

    /// The calibrated envelope's ambients, °C: `(lowest, highest)`.
    #[getter]
    fn envelope_celsius(&self) -> (f32, f32) {
        (
            self.inner.ambient_min_celsius,
            self.inner.ambient_max_celsius,
        )
    }

    /// Growth of σ per °C of switch-on ambient outside the envelope, °/s.
    #[getter]
    fn per_celsius_outside_dps(&self) -> f32 {
        self.inner.per_celsius_outside_dps
    }

    /// The most residual heat a calibration activation switched on with, per axis, °C.
    #[getter]
    fn most_residual_heat_celsius(&self) -> [f32; 3] {
        self.inner.most_residual_heat_celsius
    }

    /// Growth of σ per °C of residual heat beyond the most, °/s.
    #[getter]
    fn per_residual_celsius_beyond_dps(&self) -> f32 {
        self.inner.per_residual_celsius_beyond_dps
    }

    /// σ per sample and axis, °/s `(n, 3)` float32, for an activation switched on at
    /// `switch_on_celsius` (per axis) after what was kept of the previous one (`previous`,
    /// `(3, 2)` as `Corrector.power_on_after` takes it; None: nothing kept, a cold start), at
    /// `since_power_on_ms` (uint32 `(n,)`). Bit for bit what drift-core returns in firmware.
    #[pyo3(signature = (since_power_on_ms, switch_on_celsius, previous = None))]
    fn sigma<'py>(
        &self,
        py: Python<'py>,
        since_power_on_ms: &Bound<'py, PyAny>,
        switch_on_celsius: &Bound<'py, PyAny>,
        previous: Option<&Bound<'py, PyAny>>,
    ) -> Result<Bound<'py, PyArray2<f32>>, Error> {
        let celsius = per_axis("switch_on_celsius", switch_on_celsius)?;
        let previous: Option<[Previous; 3]> = match previous {
            Some(p) if !p.is_none() => Some(previous_arg("previous", p)?),
            _ => None,
        };
        let switch_on: [SwitchOn; 3] =
            std::array::from_fn(|a| SwitchOn::estimate(celsius[a], previous.map(|p| p[a])));
        let state = self.inner.start(&switch_on);
        let times = times("since_power_on_ms", since_power_on_ms)?;
        let view = times.as_array();
        let mut out = Vec::with_capacity(view.len() * 3);
        for &ms in view {
            out.extend(self.inner.sigma_dps(&state, ms));
        }
        Array2::from_shape_vec((view.len(), 3), out)
            .map(|a| a.into_pyarray(py))
            .map_err(|e| Error::Input(format!("internal: sigma shape: {e}")))
    }

    /// drift-core's JSON of this σ(t).
    fn to_json(&self) -> Result<String, Error> {
        model_io::to_json("Uncertainty", &self.inner)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        format!(
            "Uncertainty(envelope_celsius=({}, {}), knots={})",
            self.inner.ambient_min_celsius,
            self.inner.ambient_max_celsius,
            self.inner.knots_ms.len()
        )
    }
}

impl crate::pickle_state::Pickled for PyUncertainty {
    const KIND: &'static str = "Uncertainty";

    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        crate::pickle_state::encode(Self::KIND, &self.inner)
    }

    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let inner: Uncertainty = crate::pickle_state::decode(Self::KIND, state)?;
        inner
            .validate()
            .map_err(|e| Error::Input(format!("cannot unpickle Uncertainty: {e}")))?;
        Ok(Self { inner })
    }
}
