//! `gyrodrift.FitSettings`: how the tables are fitted (`drift_fit::FitSettings`), the same
//! settings (and defaults) as the command line's `--settings` JSON.

use drift_fit::FitSettings;
use pyo3::prelude::*;

use crate::args;
use crate::errors::Error;

/// Fitting settings; every argument left out keeps drift-fit's default (the CLI's).
#[pyclass(module = "gyrodrift", name = "FitSettings", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyFitSettings(pub FitSettings);

/// The settings behind an optional `settings` argument (defaults when left out).
pub fn or_default(value: Option<&Bound<'_, PyAny>>) -> Result<FitSettings, Error> {
    match value {
        Some(v) if !v.is_none() => v
            .cast::<PyFitSettings>()
            .map(|s| s.get().0.clone())
            .map_err(|_| {
                Error::Input(format!(
                    "`settings` must be a gyrodrift.FitSettings or None, got {}",
                    crate::arrays::describe(v)
                ))
            }),
        _ => Ok(FitSettings::default()),
    }
}

#[pymethods]
impl PyFitSettings {
    /// Settings with drift-fit's defaults for every argument left out. Ranges are checked when
    /// fitting (`FitError` naming the setting).
    #[new]
    #[pyo3(signature = (
        *,
        lowpass_window_s = None,
        grid_ms = None,
        initial_bias_window_s = None,
        switch_on_window_ms = None,
        first_reference_s = None,
        reference_count = None,
        reference_window_points = None,
        independent_after_min = None,
        polynomial_degree = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        lowpass_window_s: Option<&Bound<'_, PyAny>>,
        grid_ms: Option<&Bound<'_, PyAny>>,
        initial_bias_window_s: Option<&Bound<'_, PyAny>>,
        switch_on_window_ms: Option<&Bound<'_, PyAny>>,
        first_reference_s: Option<&Bound<'_, PyAny>>,
        reference_count: Option<&Bound<'_, PyAny>>,
        reference_window_points: Option<&Bound<'_, PyAny>>,
        independent_after_min: Option<&Bound<'_, PyAny>>,
        polynomial_degree: Option<&Bound<'_, PyAny>>,
    ) -> Result<Self, Error> {
        let mut settings = FitSettings::default();
        if let Some(v) =
            args::optional::<f64>("lowpass_window_s", "a float > 0 (s)", lowpass_window_s)?
        {
            settings.lowpass_window_s = v;
        }
        if let Some(v) = args::optional::<u32>("grid_ms", "an integer ≥ 1 (ms)", grid_ms)? {
            settings.grid_ms = v;
        }
        if let Some(v) = args::optional::<f64>(
            "initial_bias_window_s",
            "a float (s)",
            initial_bias_window_s,
        )? {
            settings.initial_bias_window_s = v;
        }
        if let Some(v) = args::optional::<u32>(
            "switch_on_window_ms",
            "an integer (ms)",
            switch_on_window_ms,
        )? {
            settings.switch_on_window_ms = v;
        }
        if let Some(v) =
            args::optional::<f64>("first_reference_s", "a float (s)", first_reference_s)?
        {
            settings.first_reference_s = v;
        }
        if let Some(v) =
            args::optional::<usize>("reference_count", "an integer in 2..=16", reference_count)?
        {
            settings.reference_count = v;
        }
        if let Some(v) = args::optional::<usize>(
            "reference_window_points",
            "an integer ≥ 1",
            reference_window_points,
        )? {
            settings.reference_window_points = v;
        }
        if let Some(v) = args::optional::<f64>(
            "independent_after_min",
            "a float (min)",
            independent_after_min,
        )? {
            settings.independent_after_min = v;
        }
        if let Some(v) =
            args::optional::<usize>("polynomial_degree", "an integer ≥ 1", polynomial_degree)?
        {
            settings.polynomial_degree = v;
        }
        Ok(Self(settings))
    }

    /// Settings from the JSON the command line's `--settings` takes (missing fields: defaults).
    #[staticmethod]
    fn from_json(text: &Bound<'_, PyAny>) -> Result<Self, Error> {
        let text = args::text("text", text)?;
        serde_json::from_str(&text)
            .map(Self)
            .map_err(|e| Error::Input(format!("`text` is not valid fit settings JSON: {e}")))
    }

    /// The JSON form (what `gyrodrift fit --settings` reads).
    fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string_pretty(&self.0)
            .map_err(|e| Error::Input(format!("internal: fit settings JSON: {e}")))
    }

    /// Low-pass window: centred moving average over this many seconds of each recording's own
    /// samples (default 1.0).
    #[getter]
    fn lowpass_window_s(&self) -> f64 {
        self.0.lowpass_window_s
    }

    /// Analysis grid: curves kept every this many ms (default 10).
    #[getter]
    fn grid_ms(&self) -> u32 {
        self.0.grid_ms
    }

    /// Initial bias: intercept of the rate against the rise over this first part, s (default 4).
    #[getter]
    fn initial_bias_window_s(&self) -> f64 {
        self.0.initial_bias_window_s
    }

    /// Switch-on temperature: mean over this first part of the activation, ms (default 20).
    #[getter]
    fn switch_on_window_ms(&self) -> u32 {
        self.0.switch_on_window_ms
    }

    /// First reference time, s (default 2).
    #[getter]
    fn first_reference_s(&self) -> f64 {
        self.0.first_reference_s
    }

    /// Reference times per axis, the first included (default 8).
    #[getter]
    fn reference_count(&self) -> usize {
        self.0.reference_count
    }

    /// Correlation samples averaged around each reference time, on the grid (default 10).
    #[getter]
    fn reference_window_points(&self) -> usize {
        self.0.reference_window_points
    }

    /// Series with at least this interval (min) are independent, like a first activation (default 15).
    #[getter]
    fn independent_after_min(&self) -> f64 {
        self.0.independent_after_min
    }

    /// Degree of the least-squares polynomial baseline (default 3).
    #[getter]
    fn polynomial_degree(&self) -> usize {
        self.0.polynomial_degree
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let s = &self.0;
        format!("FitSettings(lowpass_window_s={:?}, grid_ms={:?}, initial_bias_window_s={:?}, switch_on_window_ms={:?}, first_reference_s={:?}, reference_count={:?}, reference_window_points={:?}, independent_after_min={:?}, polynomial_degree={:?})", s.lowpass_window_s, s.grid_ms, s.initial_bias_window_s, s.switch_on_window_ms, s.first_reference_s, s.reference_count, s.reference_window_points, s.independent_after_min, s.polynomial_degree)
    }
}
