//! `gyrodrift.Settings`: sensor conversion and envelope settings stored with every model.

use drift_core::Settings;
use numpy::{IntoPyArray, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyInt};

use crate::args;
use crate::errors::Error;

/// Sensor conversion and envelope settings (`drift_core::Settings`), validated on construction.
#[pyclass(module = "gyrodrift", name = "Settings", frozen, eq)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PySettings(pub Settings);

/// Reads an optional keyword argument, or keeps the default.
fn or_default<T>(
    value: Option<&Bound<'_, PyAny>>,
    default: T,
    read: impl FnOnce(&Bound<'_, PyAny>) -> Result<T, Error>,
) -> Result<T, Error> {
    value.map_or(Ok(default), read)
}

#[pymethods]
impl PySettings {
    /// Settings with drift-core's defaults for every argument left out.
    #[new]
    #[pyo3(signature = (
        *,
        raw_per_celsius = None,
        raw_at_zero_celsius = None,
        ambient_margin_celsius = None,
        rise_margin_celsius = None,
        stuck_after_samples = None,
        sample_rate_hz = None,
    ))]
    fn new(
        raw_per_celsius: Option<&Bound<'_, PyAny>>,
        raw_at_zero_celsius: Option<&Bound<'_, PyAny>>,
        ambient_margin_celsius: Option<&Bound<'_, PyAny>>,
        rise_margin_celsius: Option<&Bound<'_, PyAny>>,
        stuck_after_samples: Option<&Bound<'_, PyAny>>,
        sample_rate_hz: Option<&Bound<'_, PyAny>>,
    ) -> Result<Self, Error> {
        let d = Settings::default();
        let settings = Settings {
            raw_per_celsius: or_default(raw_per_celsius, d.raw_per_celsius, |v| {
                args::float("raw_per_celsius", v)
            })?,
            raw_at_zero_celsius: or_default(raw_at_zero_celsius, d.raw_at_zero_celsius, |v| {
                args::float("raw_at_zero_celsius", v)
            })?,
            ambient_margin_celsius: or_default(
                ambient_margin_celsius,
                d.ambient_margin_celsius,
                |v| args::float("ambient_margin_celsius", v),
            )?,
            rise_margin_celsius: or_default(rise_margin_celsius, d.rise_margin_celsius, |v| {
                args::float("rise_margin_celsius", v)
            })?,
            stuck_after_samples: or_default(stuck_after_samples, d.stuck_after_samples, |v| {
                args::count_u16("stuck_after_samples", v)
            })?,
            sample_rate_hz: or_default(sample_rate_hz, d.sample_rate_hz, |v| {
                args::float("sample_rate_hz", v)
            })?,
        };
        settings.validate().map_err(Error::Table)?;
        Ok(Self(settings))
    }

    /// Temperature-sensor scale, raw units per °C.
    #[getter]
    fn raw_per_celsius(&self) -> f32 {
        self.0.raw_per_celsius
    }

    /// Temperature-sensor reading at 0 °C, raw units.
    #[getter]
    fn raw_at_zero_celsius(&self) -> f32 {
        self.0.raw_at_zero_celsius
    }

    /// Distance outside the calibrated ambients before flagging, °C.
    #[getter]
    fn ambient_margin_celsius(&self) -> f32 {
        self.0.ambient_margin_celsius
    }

    /// Distance outside the stored curves' rises before flagging, °C.
    #[getter]
    fn rise_margin_celsius(&self) -> f32 {
        self.0.rise_margin_celsius
    }

    /// Identical raw readings in a row that mean a stuck sensor (0: never).
    #[getter]
    fn stuck_after_samples(&self) -> u16 {
        self.0.stuck_after_samples
    }

    /// The sample rate the tables were fitted at (and `stuck_after_samples` counts at), Hz; 0: not
    /// stated.
    #[getter]
    fn sample_rate_hz(&self) -> f32 {
        self.0.sample_rate_hz
    }

    /// A raw temperature reading in °C (f32 arithmetic, as the corrector does it).
    fn celsius(&self, raw: &Bound<'_, PyAny>) -> Result<f32, Error> {
        Ok(self.0.celsius(args::float("raw", raw)?))
    }

    /// Raw temperature readings from °C, in f32 as the corrector converts them back: a float for
    /// a float, a float32 array for any array-like (a list, a numpy array, a pandas Series), so
    /// that `correct_batch` can be fed a log in °C.
    fn raw<'py>(
        &self,
        py: Python<'py>,
        celsius: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let s = self.0;
        let convert = move |c: f32| c * s.raw_per_celsius + s.raw_at_zero_celsius;
        if let Ok(value) = celsius.cast::<PyFloat>() {
            return Ok(PyFloat::new(py, f64::from(convert(value.value() as f32))).into_any());
        }
        if let Ok(value) = celsius.cast::<PyInt>() {
            let value: f64 = value.extract()?;
            return Ok(PyFloat::new(py, f64::from(convert(value as f32))).into_any());
        }
        let array = py
            .import("numpy")?
            .call_method1("asarray", (celsius, "float32"))
            .map_err(|_| {
                Error::Input(format!(
                    "`celsius` must be a float or an array of floats (°C), got {}",
                    crate::arrays::describe(celsius)
                ))
            })?;
        let array: PyReadonlyArrayDyn<'py, f32> = array.extract()?;
        Ok(array.as_array().mapv(convert).into_pyarray(py).into_any())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let s = &self.0;
        format!(
            "Settings(raw_per_celsius={:?}, raw_at_zero_celsius={:?}, ambient_margin_celsius={:?}, \
             rise_margin_celsius={:?}, stuck_after_samples={}, sample_rate_hz={:?})",
            s.raw_per_celsius,
            s.raw_at_zero_celsius,
            s.ambient_margin_celsius,
            s.rise_margin_celsius,
            s.stuck_after_samples,
            s.sample_rate_hz
        )
    }
}
