//! `gyrodrift.AnalysedActivation` and `gyrodrift.analyse`: one activation's low-frequency drift and
//! temperature rise on the analysis grid (`drift_fit::analyse`), what the fit and the figures use.

use drift_fit::analyse::{analyse as analyse_segment, Analysed};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

use crate::arrays::describe;
use crate::errors::Error;
use crate::fit_settings;
use crate::labels::PyLabels;
use crate::outputs::{columns, read_only, vector};
use crate::segment::PySegment;

/// One analysed activation: per axis, every `grid_ms` from switch-on.
#[pyclass(module = "gyrodrift", name = "AnalysedActivation", frozen)]
pub struct PyAnalysed {
    pub(crate) analysed: Analysed,
    time_s: PyOnceLock<Py<PyArray1<f64>>>,
    drift_dps: PyOnceLock<Py<PyArray2<f32>>>,
    rise_celsius: PyOnceLock<Py<PyArray2<f32>>>,
}

impl PyAnalysed {
    /// Wraps drift-fit's result.
    pub fn wrap(analysed: Analysed) -> Self {
        Self {
            analysed,
            time_s: PyOnceLock::new(),
            drift_dps: PyOnceLock::new(),
            rise_celsius: PyOnceLock::new(),
        }
    }
}

fn triple(values: [f64; 3]) -> (f64, f64, f64) {
    let [x, y, z] = values;
    (x, y, z)
}

#[pymethods]
impl PyAnalysed {
    /// The activation's labels.
    #[getter]
    fn labels(&self) -> PyLabels {
        PyLabels(self.analysed.labels.clone())
    }

    /// Spacing of the curves, ms.
    #[getter]
    fn grid_ms(&self) -> u32 {
        self.analysed.grid_ms
    }

    fn __len__(&self) -> usize {
        self.analysed.len()
    }

    /// Time of each grid point since switch-on, s (float64, (m,)). Read-only.
    #[getter]
    fn time_s(&self, py: Python<'_>) -> PyResult<Py<PyArray1<f64>>> {
        self.time_s
            .get_or_try_init(py, || {
                let times = (0..self.analysed.len())
                    .map(|i| self.analysed.time_s(i))
                    .collect();
                Ok(read_only(vector(py, times))?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Low-frequency drift g(t) = low-passed rate − initial bias, °/s (float32, (m, 3)). Read-only.
    #[getter]
    fn drift_dps(&self, py: Python<'_>) -> PyResult<Py<PyArray2<f32>>> {
        self.drift_dps
            .get_or_try_init(py, || {
                Ok(read_only(columns(py, &self.analysed.drift_dps)?)?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Temperature rise since switch-on (low-passed), °C (float32, (m, 3)). Read-only.
    #[getter]
    fn rise_celsius(&self, py: Python<'_>) -> PyResult<Py<PyArray2<f32>>> {
        self.rise_celsius
            .get_or_try_init(py, || {
                Ok(read_only(columns(py, &self.analysed.rise_celsius)?)?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Raw temperature at switch-on per axis, as firmware passes it to `power_on`.
    #[getter]
    fn switch_on_raw(&self) -> (f32, f32, f32) {
        let [x, y, z] = self.analysed.switch_on_raw;
        (x, y, z)
    }

    /// Switch-on temperature per axis, °C.
    #[getter]
    fn switch_on_celsius(&self) -> (f64, f64, f64) {
        triple(self.analysed.switch_on_celsius)
    }

    /// Initial (switch-on) bias per axis, °/s.
    #[getter]
    fn initial_bias_dps(&self) -> (f64, f64, f64) {
        triple(self.analysed.initial_bias_dps)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let l = &self.analysed.labels;
        format!(
            "<AnalysedActivation {} {:+} °C series {} repeat {} activation {}: {} points every {} ms>",
            l.unit_id,
            l.set_point_celsius,
            l.series,
            l.repeat,
            l.activation,
            self.analysed.len(),
            self.analysed.grid_ms
        )
    }
}

/// Analyses one activation as the fit does (low-pass, switch-on temperature, initial bias, drift
/// and rise on the grid). Raises `FitError` (e.g. too short).
#[pyfunction]
#[pyo3(signature = (segment, *, settings = None))]
pub fn analyse(
    py: Python<'_>,
    segment: &Bound<'_, PyAny>,
    settings: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyAnalysed> {
    let segment = segment.cast::<PySegment>().map_err(|_| {
        Error::Input(format!(
            "`segment` must be a gyrodrift.Segment, got {}",
            describe(segment)
        ))
    })?;
    let settings = fit_settings::or_default(settings)?;
    let segment = std::sync::Arc::clone(&segment.get().segment);
    let analysed = py
        .detach(|| analyse_segment(&segment, &settings))
        .map_err(Error::from)?;
    Ok(PyAnalysed::wrap(analysed))
}
