//! `gyrodrift.fit` and `gyrodrift.FittedUnit`: recordings → the paper's tables and the two
//! baselines, through drift-fit (the command line's `gyrodrift fit`, same settings and selection).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use drift_evaluate::evaluate::{evaluate_after, kept_before};
use drift_evaluate::pipeline::{self, Options};
use drift_evaluate::summary::Split;
use drift_fit::analyse::{analyse, Analysed};
use drift_fit::{fit_unit, FitSettings, FittedUnit};
use std::sync::atomic::{AtomicU64, Ordering};

use drift_recording::{Progress, Segment, SeriesKind};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::args;
use crate::arrays::describe;
use crate::errors::{Error, FitError};
use crate::fit_settings::{self, PyFitSettings};
use crate::interrupt;
use crate::results::{split_from, PyActivationResult};
use crate::segment::PySegment;
use crate::sources::{self, Source};
use crate::tables::{
    PyModifiedTables, PyPolynomialTables, PyRecommendedTables, PyRelativePolynomialTables,
};
use drift_evaluate::tables_folder;

/// Everything fitted for one unit, with the settings it was fitted with.
#[pyclass(module = "gyrodrift", name = "FittedUnit", frozen)]
#[derive(Debug)]
pub struct PyFittedUnit {
    pub unit: Arc<FittedUnit>,
    pub settings: FitSettings,
}

/// Whether a segment is a calibration activation: protocol, at a calibration set point (as the
/// pipeline decides).
fn is_calibration(segment: &Segment, set_points: &[f64]) -> bool {
    segment.labels.series_kind == SeriesKind::Protocol
        && set_points
            .iter()
            .any(|s| (s - segment.labels.set_point_celsius).abs() < 1e-6)
}

/// Fits every unit among in-memory segments, as the pipeline's first pass does for files.
/// `progress` is told each activation analysed ([`ANALYSING`]) and may stop the fit.
fn fit_segments(
    segments: &[Arc<Segment>],
    set_points: &[f64],
    settings: &FitSettings,
    progress: &dyn Progress,
) -> Result<Vec<FittedUnit>, Error> {
    let calibration: Vec<&Segment> = segments
        .iter()
        .filter(|s| is_calibration(s, set_points))
        .map(|s| &**s)
        .collect();
    let total = calibration.len() as u64;
    let analysed_so_far = AtomicU64::new(0);
    let analysed: Vec<Analysed> = calibration
        .par_iter()
        .map(|s| {
            let analysed = analyse(s, settings)?;
            let done = analysed_so_far.fetch_add(1, Ordering::Relaxed) + 1;
            progress.check(ANALYSING, done, total)?;
            Ok(analysed)
        })
        .collect::<Result<_, Error>>()?;
    let mut by_unit: BTreeMap<String, Vec<Analysed>> = BTreeMap::new();
    for a in analysed {
        by_unit.entry(a.labels.unit_id.clone()).or_default().push(a);
    }
    // The units are independent: on rayon's threads too (in unit order).
    let units: Vec<&Vec<Analysed>> = by_unit.values().collect();
    units
        .par_iter()
        .map(|activations| fit_unit(activations, settings).map_err(Error::from))
        .collect()
}

/// The step `FittedUnit.evaluate_series` reports.
const EVALUATING: &str = "evaluating";

/// The step [`fit_segments`] reports.
const ANALYSING: &str = "analysing activations";

/// Fits `source` at the calibration set points; Ctrl-C and `progress` as [`interrupt::run`].
pub fn fit_source(
    py: Python<'_>,
    source: Source,
    set_points: Vec<f64>,
    settings: FitSettings,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<PyFittedUnit>> {
    let fitted = match source {
        Source::Files(files) => {
            let options = Options {
                calibration_set_points: set_points.clone(),
                validation_set_points: Vec::new(),
                fit: settings.clone(),
                held_out_repeats: false,
                evaluate: false,
                switch_on_ambient: None,
            };
            interrupt::run(py, progress, |progress| {
                pipeline::run(&files, &options, false, progress)
            })?
            .map_err(Error::from)?
            .fitted
        }
        Source::Segments(segments) => {
            let fitted = interrupt::run(py, progress, |progress| {
                fit_segments(&segments, &set_points, &settings, progress)
            })??;
            if fitted.is_empty() {
                return Err(FitError::new_err(format!(
                    "no protocol activations at the calibration set points {set_points:?} °C in {} segments",
                    segments.len()
                )));
            }
            fitted
        }
    };
    Ok(fitted
        .into_iter()
        .map(|unit| PyFittedUnit {
            unit: Arc::new(unit),
            settings: settings.clone(),
        })
        .collect())
}

/// Fits the paper's tables and both baselines for every unit in `source`, on the protocol
/// activations at the `calibration` set points (the command line's `gyrodrift fit`). Returns one
/// `FittedUnit` per unit, sorted by unit id. The GIL is released while fitting; Ctrl-C stops it
/// within a second, and `progress(step, done, total)` is told how far it got.
#[pyfunction]
#[pyo3(signature = (source, *, calibration = None, settings = None, progress = None))]
pub fn fit(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    calibration: Option<&Bound<'_, PyAny>>,
    settings: Option<&Bound<'_, PyAny>>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<PyFittedUnit>> {
    let progress = interrupt::callable(progress)?;
    let source = sources::source(py, "source", source)?;
    let set_points = match calibration {
        Some(v) => sources::set_points("calibration", v, false)?,
        None => drift_recording::paper::CALIBRATION_SET_POINTS_CELSIUS.to_vec(),
    };
    let settings = fit_settings::or_default(settings)?;
    fit_source(py, source, set_points, settings, progress.as_ref())
}

#[pymethods]
impl PyFittedUnit {
    /// Unit id.
    #[getter]
    fn unit_id(&self) -> &str {
        &self.unit.unit_id
    }

    /// The paper's ("modified") tables.
    #[getter]
    fn modified(&self) -> PyModifiedTables {
        PyModifiedTables(Arc::new(self.unit.modified.clone()))
    }

    /// The same curves with stage 3 keyed by heating history (each curve labelled by the residual
    /// heat it switched on with): for firmware that keeps what it knew of the previous activation
    /// (`Corrector.power_on_after`).
    #[getter]
    fn by_history(&self) -> PyModifiedTables {
        PyModifiedTables(Arc::new(self.unit.by_history.clone()))
    }

    /// The paper's standard calibration (Lagrange polynomial through the set points).
    #[getter]
    fn standard(&self) -> PyPolynomialTables {
        PyPolynomialTables(Arc::new(self.unit.standard.clone()))
    }

    /// The least-squares polynomial baseline (3rd order by default).
    #[getter]
    fn third_order(&self) -> PyPolynomialTables {
        PyPolynomialTables(Arc::new(self.unit.third_order.clone()))
    }

    /// The least-squares baseline relative to the switch-on (bias = q(T_on) + p(T) − p(T_on)),
    /// orders chosen by leave-one-series-out cross-validation on the calibration data.
    #[getter]
    fn relative(&self) -> PyRelativePolynomialTables {
        PyRelativePolynomialTables(Arc::new(self.unit.relative.clone()))
    }

    /// The recommended model: the paper's curves with the turn-on bias fitted on every
    /// calibration activation (`recommended.bin`).
    #[getter]
    fn recommended(&self) -> PyRecommendedTables {
        PyRecommendedTables(Arc::new(self.unit.recommended.clone()))
    }

    /// The settings the unit was fitted with (used again by `evaluate`).
    #[getter]
    fn settings(&self) -> PyFitSettings {
        PyFitSettings(self.settings.clone())
    }

    /// Calibration set points, °C, in table order.
    #[getter]
    fn set_points_celsius(&self) -> Vec<f64> {
        self.unit
            .set_points
            .iter()
            .map(|s| s.set_point_celsius)
            .collect()
    }

    /// The curves kept, in table order: "independent" or "<interval>min#<activation>".
    #[getter]
    fn curve_names(&self) -> Vec<String> {
        self.unit.curve_keys.iter().map(|k| k.name()).collect()
    }

    /// Things the fit decided that a reader should know (dropped curves, nudged ties).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.unit.notes.clone()
    }

    /// Corrects one activation with every model (drift-core's f32 corrector) and measures the
    /// paper's drift metric; `split` labels the result for `summarise`. The history-keyed model
    /// ("by-history") starts from `previous` (what firmware kept of the previous activation, a
    /// `(3, 2)` array as `Corrector.power_on_after` takes and `Corrector.keep` returns); without
    /// it, with nothing kept (a cold start, flagged).
    #[pyo3(signature = (segment, *, split = None, previous = None))]
    fn evaluate(
        &self,
        py: Python<'_>,
        segment: &Bound<'_, PyAny>,
        split: Option<&Bound<'_, PyAny>>,
        previous: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<PyActivationResult> {
        let segment = segment.cast::<PySegment>().map_err(|_| {
            Error::Input(format!(
                "`segment` must be a gyrodrift.Segment, got {}",
                describe(segment)
            ))
        })?;
        let split = match split {
            Some(v) if !v.is_none() => split_from(v)?,
            _ => Split::Validation,
        };
        let previous = match previous {
            Some(v) if !v.is_none() => crate::corrector::previous_arg("previous", v)?,
            _ => drift_core::Previous::NOTHING,
        };
        let segment = Arc::clone(&segment.get().segment);
        let result = py.detach(|| evaluate_after(&self.unit, &segment, &self.settings, &previous));
        Ok(PyActivationResult { split, result })
    }

    /// Corrects a recording's activations (`segments`, one unit's) with every model, as
    /// `gyrodrift report` does: the history-keyed model starts each from what firmware kept of the
    /// one before in switch-on order, knowing a full cool-down from the recorded off-time; results
    /// in the order given. The GIL is released, and Ctrl-C stops it between activations.
    #[pyo3(signature = (segments, *, split = None))]
    fn evaluate_series(
        &self,
        py: Python<'_>,
        segments: &Bound<'_, PyAny>,
        split: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<PyActivationResult>> {
        let split = match split {
            Some(v) if !v.is_none() => split_from(v)?,
            _ => Split::Validation,
        };
        let mut owned = Vec::new();
        for (i, item) in segments.try_iter()?.enumerate() {
            let item = item?;
            let segment = item.cast::<PySegment>().map_err(|_| {
                Error::Input(format!(
                    "`segments[{i}]` must be a gyrodrift.Segment, got {}",
                    describe(&item)
                ))
            })?;
            owned.push(Arc::clone(&segment.get().segment));
        }
        let results = interrupt::run(py, None, |progress| {
            let refs: Vec<&drift_recording::Segment> = owned.iter().map(|s| &**s).collect();
            let kept = kept_before(&refs, &self.settings, &self.unit.by_history.settings, true);
            let total = refs.len() as u64;
            refs.iter()
                .zip(&kept)
                .enumerate()
                .map(|(i, (segment, previous))| {
                    progress.check(EVALUATING, i as u64, total)?;
                    Ok(evaluate_after(
                        &self.unit,
                        segment,
                        &self.settings,
                        previous,
                    ))
                })
                .collect::<Result<Vec<_>, drift_recording::Interrupted>>()
        })?
        .map_err(Error::from)?;
        Ok(results
            .into_iter()
            .map(|result| PyActivationResult { split, result })
            .collect())
    }

    /// Diagnoses what the paper's model leaves in the residual of this unit's activations among
    /// `segments` (recordings, segments or files; other units' activations are skipped), as
    /// `gyrodrift diagnose` does: candidates ranked on the field-like activations at the
    /// calibration set points inside the calibrated ambient range (else on every activation the
    /// fit did not see); with `extend`, the guarded extended model and its error before and after
    /// on the held-out activations. `diagnose_on` names set points whose series (field and
    /// protocol) are the diagnosis data, cross-fitted by series: `half` (0 or 1) is the half this
    /// loop ranks and fits on, the other half judges. `bench_channels` are context, never ranked
    /// (the chamber's set point and air always are). Like the command line, the loop works on the
    /// activations' 0.1-s block means and refits this unit's paper tables on its calibration
    /// protocol among them. The GIL is released; Ctrl-C stops the loop within a second while it
    /// reads or ranks and between its steps, and `progress(step, done, total)` is told how far it
    /// got.
    #[pyo3(signature = (segments, *, calibration = None, extend = false, diagnose_on = Vec::new(), half = 0, bench_channels = Vec::new(), progress = None))]
    #[allow(clippy::too_many_arguments)]
    fn diagnose(
        &self,
        py: Python<'_>,
        segments: &Bound<'_, PyAny>,
        calibration: Option<&Bound<'_, PyAny>>,
        extend: bool,
        diagnose_on: Vec<f64>,
        half: usize,
        bench_channels: Vec<String>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<crate::diagnosis::PyDiagnosis> {
        let progress = interrupt::callable(progress)?;
        if half > 1 {
            return Err(crate::errors::Error::Input(format!(
                "`half` must be 0 or 1 (which half of the diagnosis series ranks), got {half}"
            ))
            .into());
        }
        crate::diagnosis::diagnose_unit(
            py,
            &self.unit,
            &self.settings,
            segments,
            calibration,
            crate::diagnosis::Asked {
                extend,
                diagnose_on,
                half,
                bench_channels,
            },
            progress.as_ref(),
        )
    }

    /// Writes `<folder>/<unit_id>/{modified,by_history,standard,third_order}.{json,bin}`
    /// (`drift_evaluate::tables_folder`, the command line's writer); returns the unit's folder.
    fn save(&self, folder: &Bound<'_, PyAny>) -> Result<PathBuf, Error> {
        let folder = args::path("folder", folder)?;
        let files = tables_folder::unit_files(&folder, &self.unit)?;
        tables_folder::write_files(&files)?;
        Ok(folder.join(&self.unit.unit_id))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        format!(
            "<FittedUnit {}: {} curves × {} ambients>",
            self.unit.unit_id,
            self.unit.curve_keys.len(),
            self.unit.set_points.len()
        )
    }
}
