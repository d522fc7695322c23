//! `gyrodrift.evaluate` (the command line's `gyrodrift report` without the files: fit, then
//! correct everything the fit did not see), `gyrodrift.Evaluation`, `gyrodrift.ActivationResult`
//! and `gyrodrift.summarise` (the report's table as data, the records of `report.json`).

use std::path::PathBuf;
use std::sync::Arc;

use drift_evaluate::evaluate::ActivationResult;
use drift_evaluate::pipeline::{self, Options};
use drift_evaluate::summary::{summarise as summarise_results, Split};
use drift_recording::paper;
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::analysed::PyAnalysed;
use crate::args;
use crate::arrays::describe;
use crate::errors::Error;
use crate::fit::PyFittedUnit;
use crate::fit_settings;
use crate::interrupt;
use crate::results::PyActivationResult;
use crate::sources::{self, Source};

/// The records of `report.json` as Python dicts (same keys and values).
fn records_of<'py>(
    py: Python<'py>,
    results: &[(Split, ActivationResult)],
) -> PyResult<Bound<'py, PyAny>> {
    let records = summarise_results(results);
    let text = serde_json::to_string(&records)
        .map_err(|e| Error::Input(format!("internal: records JSON: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Averages activation results into the report's records: one dict per unit × set point ×
/// split × model × axis with `drift_dps`, `residual_rms_dps` and `activations`.
#[pyfunction]
pub fn summarise<'py>(py: Python<'py>, results: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let items: Vec<Bound<'py, PyAny>> = args::value(
        "results",
        "a sequence of gyrodrift.ActivationResult",
        results,
    )?;
    let mut all = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let result = item.cast::<PyActivationResult>().map_err(|_| {
            Error::Input(format!(
                "`results[{i}]` must be a gyrodrift.ActivationResult, got {}",
                describe(item)
            ))
        })?;
        let r = result.get();
        all.push((r.split, r.result.clone()));
    }
    records_of(py, &all)
}

/// What `evaluate` found: the fitted units, the analysed calibration activations and every
/// evaluated activation, with the report's table as records.
#[pyclass(module = "gyrodrift", name = "Evaluation", frozen)]
pub struct PyEvaluation {
    pub(crate) fitted: Vec<Py<PyFittedUnit>>,
    pub(crate) calibration: Vec<Py<PyAnalysed>>,
    pub(crate) results: Vec<(Split, ActivationResult)>,
    pub(crate) noise_floor_units: Vec<String>,
    pub(crate) timings: Vec<(String, f64)>,
}

#[pymethods]
impl PyEvaluation {
    /// Tables fitted on all calibration activations, one per unit (sorted by unit id).
    #[getter]
    fn fitted<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.fitted.iter().map(|f| f.clone_ref(py)))
    }

    /// The calibration activations, analysed (what the fit and the paper's figures use).
    #[getter]
    fn calibration<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.calibration.iter().map(|a| a.clone_ref(py)))
    }

    /// Every evaluated activation with its split.
    #[getter]
    fn results(&self) -> Vec<PyActivationResult> {
        self.results
            .iter()
            .map(|(split, result)| PyActivationResult {
                split: *split,
                result: result.clone(),
            })
            .collect()
    }

    /// The report's table as data (the records of `report.json`): a new list of dicts.
    #[getter]
    fn records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        records_of(py, &self.results)
    }

    /// The records as a pandas DataFrame (needs pandas; raises ImportError without it).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas").map_err(|error| {
            pyo3::exceptions::PyImportError::new_err(format!(
                "Evaluation.to_dataframe needs pandas (pip install pandas): {error}"
            ))
        })?;
        pandas.call_method1("DataFrame", (records_of(py, &self.results)?,))
    }

    /// Unit ids of the noise-floor units ("noise:<id>"), if `noise_floor` was given.
    #[getter]
    fn noise_floor_units(&self) -> Vec<String> {
        self.noise_floor_units.clone()
    }

    /// Measured durations of the pipeline's steps: (step, seconds).
    #[getter]
    fn timings(&self) -> Vec<(String, f64)> {
        self.timings.clone()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        format!(
            "<Evaluation: {} units fitted, {} calibration activations, {} evaluated>",
            self.fitted.len(),
            self.calibration.len(),
            self.results.len()
        )
    }
}

/// The recording files, the noise-floor twin's files and the pipeline's options that `evaluate`
/// and `report` take from their arguments.
#[allow(clippy::type_complexity)]
fn pipeline_inputs(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    noise_floor: Option<&Bound<'_, PyAny>>,
    calibration: Option<&Bound<'_, PyAny>>,
    validation: Option<&Bound<'_, PyAny>>,
    settings: Option<&Bound<'_, PyAny>>,
    held_out_repeats: bool,
) -> Result<(Vec<PathBuf>, Option<Vec<PathBuf>>, Options), Error> {
    let Source::Files(files) = sources::source(py, "source", source)? else {
        return Err(Error::Input(
            "`source` must be recording files (a campaign folder, a folder of .mcap files or a \
             list of files): the pipeline reads them twice, as `gyrodrift report` does; for \
             recordings in memory use FittedUnit.evaluate and summarise"
                .into(),
        ));
    };
    let noise_files = match noise_floor.filter(|n| !n.is_none()) {
        None => None,
        Some(value) => match sources::source(py, "noise_floor", value)? {
            Source::Files(files) => Some(files),
            Source::Segments(_) => {
                return Err(Error::Input(format!(
                    "`noise_floor` must be a path to recording files, got {}",
                    describe(value)
                )))
            }
        },
    };
    let options = Options {
        calibration_set_points: match calibration {
            Some(v) => sources::set_points("calibration", v, false)?,
            None => paper::CALIBRATION_SET_POINTS_CELSIUS.to_vec(),
        },
        validation_set_points: match validation {
            Some(v) => sources::set_points("validation", v, true)?,
            None => vec![paper::VALIDATION_SET_POINT_CELSIUS],
        },
        fit: fit_settings::or_default(settings)?,
        held_out_repeats,
        evaluate: true,
        switch_on_ambient: None,
    };
    Ok((files, noise_files, options))
}

/// Writes the report of `gyrodrift report` into `out` — `report.md` with its figures,
/// `report.json`, `timings.json` and the tables folder `tables/` — through the same function, so
/// the same recordings and options give the same bytes; returns the path of `report.md`. `source`
/// is a campaign folder, a folder of `.mcap` files or a list of files; `noise_floor` a campaign of
/// zero-drift units measured like it. The GIL is released; Ctrl-C stops it within a second, before
/// anything is written, and `progress(step, done, total)` is told how far it got.
#[pyfunction]
#[pyo3(signature = (source, out, *, calibration = None, validation = None, settings = None, noise_floor = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn report(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    out: &Bound<'_, PyAny>,
    calibration: Option<&Bound<'_, PyAny>>,
    validation: Option<&Bound<'_, PyAny>>,
    settings: Option<&Bound<'_, PyAny>>,
    noise_floor: Option<&Bound<'_, PyAny>>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<PathBuf> {
    let progress = interrupt::callable(progress)?;
    let out = args::path("out", out)?;
    let (files, noise_files, options) = pipeline_inputs(
        py,
        source,
        noise_floor,
        calibration,
        validation,
        settings,
        true,
    )?;
    let described = describe_source(source);
    interrupt::run(py, progress.as_ref(), |progress| {
        drift_report::make(
            &files,
            noise_files.as_deref(),
            &options,
            &out,
            drift_report::provenance(&described, &options),
            progress,
        )
    })?
    .map(|(path, _)| path)
    .map_err(|error| match error.downcast::<pipeline::PipelineError>() {
        Ok(error) => Error::from(error).into(),
        Err(error) => Error::Report(format!("{error:#}")).into(),
    })
}

/// A source as the report's provenance names it: the path as given, or the number of files.
fn describe_source(source: &Bound<'_, PyAny>) -> String {
    match source.extract::<PathBuf>() {
        Ok(path) => path.display().to_string(),
        Err(_) => format!("{} files", source.len().unwrap_or(0)),
    }
}

/// Fits on the calibration set points and evaluates every activation no fit saw, as
/// `gyrodrift report` does: validation set points, field sessions, and (with `held_out_repeats`)
/// each repeat at the calibration set points against tables refitted without it. `source` is a
/// campaign folder, a folder of `.mcap` files or a list of files; `noise_floor` a campaign of
/// zero-drift units measured at the validation set points. The GIL is released; Ctrl-C stops it
/// within a second, and `progress(step, done, total)` is told how far it got.
#[pyfunction]
#[pyo3(signature = (source, *, calibration = None, validation = None, settings = None, held_out_repeats = true, noise_floor = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    calibration: Option<&Bound<'_, PyAny>>,
    validation: Option<&Bound<'_, PyAny>>,
    settings: Option<&Bound<'_, PyAny>>,
    held_out_repeats: bool,
    noise_floor: Option<&Bound<'_, PyAny>>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyEvaluation> {
    let progress = interrupt::callable(progress)?;
    let (files, noise_files, options) = pipeline_inputs(
        py,
        source,
        noise_floor,
        calibration,
        validation,
        settings,
        held_out_repeats,
    )?;
    let (outcome, noise_floor_units) = interrupt::run(py, progress.as_ref(), |progress| {
        pipeline::run_with_noise_floor(&files, noise_files.as_deref(), &options, progress)
    })?
    .map_err(Error::from)?;
    let fitted = outcome
        .fitted
        .into_iter()
        .map(|unit| {
            Py::new(
                py,
                PyFittedUnit {
                    unit: Arc::new(unit),
                    settings: options.fit.clone(),
                },
            )
        })
        .collect::<PyResult<_>>()?;
    let calibration = outcome
        .calibration
        .into_iter()
        .map(|a| Py::new(py, PyAnalysed::wrap(a)))
        .collect::<PyResult<_>>()?;
    Ok(PyEvaluation {
        fitted,
        calibration,
        results: outcome.results,
        noise_floor_units,
        timings: outcome.timings,
    })
}
