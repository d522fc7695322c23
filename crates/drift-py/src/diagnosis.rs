//! `FittedUnit.diagnose` and `gyrodrift.Diagnosis`: the command line's `gyrodrift diagnose
//! [--extend]` for one unit, through drift-fit's `closing` (roles → diagnosis → guarded extended
//! model → error before and after). Conversion and delegation only.

use std::sync::Arc;

use drift_core::ModifiedTables;
use drift_diagnose::activations::{at_diagnosis_rate, loop_settings, read_by_unit};
use drift_diagnose::closing::PROFILE_EDGES_S;
use drift_diagnose::closing::{close, LoopOptions};
use drift_diagnose::diagnose::AxisDiagnosis;
use drift_diagnose::extend::Admission;
use drift_diagnose::roles::Roles;
use drift_fit::analyse::{analyse, Analysed};
use drift_fit::{fit_unit, FitSettings, FittedUnit};
use drift_recording::{Progress, Segment};
use drift_report::diagnosis::{Request, Section};
use numpy::ndarray::Array3;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};

use crate::errors::Error;
use crate::interrupt;
use crate::outputs::vector;
use crate::pickle_state::{self, Pickled};
use crate::sources::{self, Source};
use crate::tables::PyModifiedTables;

/// What the diagnosis found for one unit, and the extended model when one was asked for.
///
/// Held as owned data (records as JSON text, the model as tables) so that it pickles.
#[pyclass(module = "gyrodrift", name = "Diagnosis", frozen)]
#[derive(Debug, Serialize, Deserialize)]
pub struct PyDiagnosis {
    unit_id: String,
    /// JSON records of `ranking` and `paper_ranking`.
    ranking: String,
    paper_ranking: String,
    /// Per axis, the significant winner.
    chosen: Vec<(String, Option<String>)>,
    proposed: Vec<String>,
    /// JSON records of `admissions`, `stage3`, `warm_start`, `before_after`.
    admissions: String,
    stage3: String,
    warm_start: String,
    before_after: String,
    extended: Option<Box<ModifiedTables>>,
    /// The command line's line on the extended model; None without `extend`.
    extended_verdict: Option<String>,
    aux_inputs: Vec<String>,
    profiles: Vec<ProfileRow>,
    counts: Vec<(String, usize)>,
    /// The unit's part of `diagnosis.md`/`.json` and its files, rendered as the command line
    /// renders them (`drift_report::diagnosis`).
    report: Section,
}

/// One held-out activation's residual profile ([`Profile`], owned).
#[derive(Debug, Serialize, Deserialize)]
struct ProfileRow {
    set_point_celsius: f64,
    series_kind: String,
    off_before_s: Option<f64>,
    after_dps: [Vec<f64>; 3],
}

/// JSON text of serialisable records (NaN becomes null, as in `report.json`).
fn json(value: &impl Serialize) -> Result<String, Error> {
    serde_json::to_string(value).map_err(|e| Error::Input(format!("internal: records JSON: {e}")))
}

/// JSON records as Python objects (lists and dicts).
fn to_python<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// One row of the ranking, flat for a DataFrame.
#[derive(Serialize)]
struct RankRecord<'a> {
    axis: &'static str,
    rank: usize,
    candidate: &'a str,
    level: &'static str,
    explained: f64,
    family_p_value: f64,
    p_value: f64,
    whole_p_value: f64,
    drift_p_value: f64,
    significant: bool,
    thermal_response: bool,
    stable: bool,
    detectable_share: f64,
    size_threshold: f64,
    baseline_explained_within: f64,
    baseline_explained_between: f64,
    coefficient: f64,
    absorbed_by_model: f64,
}

/// The step of averaging activations in memory into their block means.
const AVERAGING: &str = "averaging activations";

/// The activations of `unit_id` among `segments` at the loop's rate (0.1-s block means,
/// [`drift_diagnose::activations`]), with how many activations of other units there were: files
/// are read one activation at a time, objects in memory are averaged into copies.
fn activations(
    source: Source,
    unit_id: &str,
    progress: &dyn Progress,
) -> Result<(Vec<Segment>, usize), Error> {
    match source {
        Source::Segments(segments) => {
            let total = segments.len() as u64;
            let (mut own, mut others) = (Vec::new(), 0);
            for (i, segment) in segments.iter().enumerate() {
                progress.check(AVERAGING, i as u64, total)?;
                if segment.labels.unit_id == unit_id {
                    own.push(at_diagnosis_rate(Segment::clone(segment)));
                } else {
                    others += 1;
                }
            }
            Ok((own, others))
        }
        Source::Files(files) => {
            let mut by_unit = read_by_unit(&files, progress)?;
            let own = by_unit.remove(unit_id).unwrap_or_default();
            Ok((own, by_unit.values().map(Vec::len).sum()))
        }
    }
}

/// The paper's tables of the unit refitted on its calibration protocol among `own` (at the loop's
/// rate, with the loop's settings), as `gyrodrift diagnose` fits them; the tables state the rate
/// the activations were recorded at, `recorded_hz`.
fn loop_tables(
    own: &[&Segment],
    set_points: &[f64],
    settings: &FitSettings,
    recorded_hz: u32,
) -> Result<FittedUnit, Error> {
    let analysed = Roles::split(own.iter().copied(), set_points)
        .calibration
        .iter()
        .map(|s| {
            analyse(s, settings).map(|a| Analysed {
                sample_rate_hz: recorded_hz,
                ..a
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(fit_unit(&analysed, settings)?)
}

/// What `FittedUnit.diagnose` was asked beyond its data.
pub struct Asked {
    /// Build, guard and measure the extended model.
    pub extend: bool,
    /// Set points whose series are the diagnosis data, cross-fitted.
    pub diagnose_on: Vec<f64>,
    /// The half of the diagnosis series this loop ranks on.
    pub half: usize,
    /// Channels of the bench, never ranked (beside the default ones).
    pub bench_channels: Vec<String>,
}

/// Runs the loop for `unit` on its activations among `segments`.
pub fn diagnose_unit(
    py: Python<'_>,
    unit: &FittedUnit,
    settings: &FitSettings,
    segments: &Bound<'_, PyAny>,
    calibration: Option<&Bound<'_, PyAny>>,
    asked: Asked,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyDiagnosis> {
    let source = sources::source(py, "segments", segments)?;
    let set_points = match calibration {
        Some(v) if !v.is_none() => sources::set_points("calibration", v, false)?,
        _ => unit
            .set_points
            .iter()
            .map(|s| s.set_point_celsius)
            .collect(),
    };
    // The loop runs on the work's thread, whose stack is sized for it: its host types (tables of
    // every model, refitted per candidate and fold) are values of hundreds of KB, and on the
    // interpreter's main thread, whose stack Python's own frames share, they overflowed it.
    let diagnosis = interrupt::run(py, progress, |progress| {
        run_loop(unit, settings, source, &set_points, &asked, progress)
    })??;
    Ok(diagnosis)
}

/// The steps of the loop after reading, as its progress reports them (one unit each).
const LOOP_STEPS: [&str; 3] = [
    "fitting the loop's tables",
    "ranking, fitting and guarding",
    "measuring before and after",
];

/// The loop itself, off the interpreter's thread.
fn run_loop(
    unit: &FittedUnit,
    settings: &FitSettings,
    source: Source,
    set_points: &[f64],
    asked: &Asked,
    progress: &dyn Progress,
) -> Result<PyDiagnosis, Error> {
    let extend = asked.extend;
    let step = |done: usize| {
        let total = LOOP_STEPS.len() as u64;
        progress.check(
            LOOP_STEPS[done.min(LOOP_STEPS.len() - 1)],
            done as u64,
            total,
        )
    };
    {
        let recorded_hz = unit.modified.settings.sample_rate_hz as u32;
        let (own, others) = activations(source, &unit.unit_id, progress)?;
        if own.is_empty() {
            return Err(Error::Input(format!(
                "`segments` holds no activation of unit {} ({others} activations of other units)",
                unit.unit_id,
            )));
        }
        let own: Vec<&Segment> = own.iter().collect();
        // The loop's own tables, fitted as the command line fits them (on the block means, with
        // the loop's settings): the same data give the command line's diagnosis.
        let settings = &loop_settings(settings);
        step(0)?;
        let base = loop_tables(&own, set_points, settings, recorded_hz)?;
        step(1)?;
        let unit = &base;
        let mut options = LoopOptions {
            extend,
            diagnose_on: asked.diagnose_on.clone(),
            half: asked.half,
            ..LoopOptions::new(set_points)
        };
        options
            .bench_channels
            .extend(asked.bench_channels.iter().cloned());
        let closed = close(unit, own, &[], &options, settings, progress)?;
        step(2)?;
        if closed.series.is_empty() {
            return Err(Error::Input(format!(
                "`segments` holds no activation of unit {} outside the calibration protocol at {set_points:?} °C to diagnose",
                unit.unit_id
            )));
        }
        let admitted = closed
            .extended
            .as_ref()
            .filter(|e| !e.plan.terms.is_empty());
        // The loop's model differs from the paper's when a term was admitted, or stage 3 or the
        // initial bias reads the heating history on an axis.
        let changed = admitted.is_some() || closed.keying.any();
        let before_after = if changed {
            closed.before_after(unit, settings)
        } else {
            Vec::new()
        };
        let chosen = closed
            .axes
            .iter()
            .map(|a| (a.axis.to_owned(), a.chosen().map(|c| c.name.clone())))
            .collect();
        let profiles = closed
            .profiles(unit, settings)
            .into_iter()
            .map(|p| ProfileRow {
                set_point_celsius: p.set_point_celsius,
                series_kind: p.series_kind.to_owned(),
                off_before_s: p.off_before_s,
                after_dps: p.after_dps,
            })
            .collect();
        let admissions: Vec<Admission> = closed
            .extended
            .as_ref()
            .map(|e| e.admissions.clone())
            .unwrap_or_default();
        let request = Request {
            top: REPORT_TOP,
            extend,
            select_on: &[],
            evaluation_data: None,
        };
        let report = drift_report::diagnosis::unit_section(
            &unit.unit_id,
            &closed,
            unit,
            settings,
            &request,
            None,
        )
        .map_err(|e| Error::Input(format!("rendering the diagnosis: {e:#}")))?;
        Ok(PyDiagnosis {
            report,
            unit_id: unit.unit_id.clone(),
            ranking: json(&records(&closed.axes))?,
            paper_ranking: json(&records(&closed.paper_axes))?,
            chosen,
            proposed: closed
                .proposed
                .terms
                .iter()
                .map(|t| t.candidate.clone())
                .collect(),
            admissions: json(&admissions)?,
            extended: changed.then(|| closed.model(unit)),
            extended_verdict: extend
                .then(|| drift_report::diagnosis::extended_verdict(unit, &closed)),
            stage3: json(&closed.stage3)?,
            warm_start: json(&closed.warm_start)?,
            aux_inputs: admitted
                .map(|e| e.plan.aux_inputs.clone())
                .unwrap_or_default(),
            before_after: json(&before_after)?,
            profiles,
            counts: [
                ("calibration", closed.roles.calibration.len()),
                ("training", closed.roles.training.len()),
                ("held_out", closed.roles.held_out.len()),
                ("outside_range", closed.roles.outside_range),
                ("diagnosed", closed.series.len()),
            ]
            .map(|(name, n)| (name.to_owned(), n))
            .to_vec(),
        })
    }
}

/// Candidates listed per axis in the saved report, as `gyrodrift diagnose` lists by default.
const REPORT_TOP: usize = 5;

#[pymethods]
impl PyDiagnosis {
    /// Writes `diagnosis.md`, `diagnosis.json` and the residual figures (and, with `extend=True`,
    /// the extended model's image) into `folder`, as `gyrodrift diagnose` writes them; returns
    /// the path of `diagnosis.md`.
    fn save(&self, folder: &Bound<'_, PyAny>) -> Result<std::path::PathBuf, Error> {
        let folder = crate::args::path("folder", folder)?;
        let sections = std::slice::from_ref(&self.report);
        let document = drift_report::diagnosis::document("", sections, "");
        drift_report::diagnosis::write(&folder, &document, sections)
            .map_err(|e| Error::Input(format!("{}: {e:#}", folder.display())))?;
        Ok(folder.join("diagnosis.md"))
    }

    /// Unit id.
    #[getter]
    fn unit_id(&self) -> &str {
        &self.unit_id
    }

    /// The ranking of every axis as records (axis, rank, candidate, level, explained,
    /// family_p_value, p_value, whole_p_value, drift_p_value, significant, thermal_response,
    /// stable, detectable_share, size_threshold, baseline_explained_within,
    /// baseline_explained_between, coefficient, absorbed_by_model): a new list of dicts.
    /// `explained` is the candidate's out-of-sample gain over the baseline (the paper model's
    /// ambient gap and the bench's context channels, fitted first); `significant` marks the
    /// candidates selected forward: significant family-wise (`family_p_value` ≤ 0.05, shuffles of
    /// whole series) and with a gain of at least `size_threshold` (its step's, from null worlds).
    /// `thermal_response` marks the unit's own thermal response (its rise squared, its own axis's
    /// temperature rate), selected before any effect; every other candidate is an effect, scored
    /// over the baseline and the thermal response selected. `detectable_share` is the gain an
    /// effect on that axis must exceed with these activations. The t-tests' p-values are
    /// reported, not gated on.
    #[getter]
    fn ranking<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.ranking)
    }

    /// The same diagnosis behind the paper's own model (stage 3 keyed by rise, the paper's
    /// initial bias), as records like `ranking`: what the paper's model lacked, which the loop's
    /// choices (`stage3`, `warm_start`) and terms answer. Equal to `ranking` when the loop kept
    /// the paper's model.
    #[getter]
    fn paper_ranking<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.paper_ranking)
    }

    /// The ranking as a pandas DataFrame (needs pandas; raises ImportError without it).
    fn to_dataframe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas").map_err(|error| {
            pyo3::exceptions::PyImportError::new_err(format!(
                "Diagnosis.to_dataframe needs pandas (pip install pandas): {error}"
            ))
        })?;
        pandas.call_method1("DataFrame", (to_python(py, &self.ranking)?,))
    }

    /// Per axis ("X", "Y", "Z"), the significant winning effect's name, or None when no
    /// significant systematic effect is left beyond the unit's own thermal response.
    #[getter]
    fn chosen(&self) -> Vec<(String, Option<String>)> {
        self.chosen.clone()
    }

    /// The terms proposed for the extended model: the diagnosis's significant candidates that
    /// drift-core can compute.
    #[getter]
    fn proposed_terms(&self) -> Vec<String> {
        self.proposed.clone()
    }

    /// The guard's decision for every proposed term and axis (records: candidate, axis,
    /// improvement, p_value, drift_gain_dps, drift_p_value, admitted); empty unless
    /// `extend=True`. A shape term (rate, rise², another axis's rise) is admitted on
    /// `drift_p_value`, an auxiliary input on `p_value`.
    #[getter]
    fn admissions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.admissions)
    }

    /// Per axis, stage 3's lookup as the loop chose it on the training activations (records:
    /// axis, curves_cross, training_activations, training_drift_by_rise_dps,
    /// training_drift_by_history_dps, p_value, keyed_by_history).
    #[getter]
    fn stage3<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.stage3)
    }

    /// Per axis, whether the loop took the initial bias of warm starts from the calibration's
    /// series, chosen on the training activations after stage 3 (records: axis,
    /// training_activations, training_rms_cold_dps, training_rms_warm_dps, p_value, chosen).
    #[getter]
    fn warm_start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.warm_start)
    }

    /// The loop's model (stage 3 keyed and the initial bias taken as chosen, the refitted tables
    /// with the admitted terms), or None when it is the paper's unchanged. Axes that read the
    /// heating history need `power_on_after`.
    #[getter]
    fn extended(&self) -> Option<PyModifiedTables> {
        self.extended
            .clone()
            .map(|m| PyModifiedTables(Arc::from(m)))
    }

    /// What became of the extended model, as `gyrodrift diagnose --extend` prints it: why nothing
    /// was extended (e.g. "no term proposed (nothing significant maps to a term the firmware can
    /// compute); the paper's model unchanged") or which terms were admitted; None unless
    /// `extend=True`.
    #[getter]
    fn extended_verdict(&self) -> Option<String> {
        self.extended_verdict.clone()
    }

    /// The recorded channels the firmware passes as the extended model's auxiliary inputs 0..,
    /// in order.
    #[getter]
    fn aux_inputs(&self) -> Vec<String> {
        self.aux_inputs.clone()
    }

    /// Per held-out activation, the error before (paper's model) and after (extended model):
    /// records with set_point_celsius, series_kind, drift_dps, rms_dps and mean_dps (per axis,
    /// [before, after]; the mean is the activation's offset), by_history_drift_dps,
    /// by_history_rms_dps, residual_heat_celsius (per axis, as firmware estimates it at switch-on)
    /// and off_before_s (the recording's label, or None); empty unless `extend=True` and terms
    /// were proposed.
    #[getter]
    fn before_after<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.before_after)
    }

    /// Where within each held-out activation the loop's residual sits, by time since switch-on: a
    /// dict of numpy arrays — `edges_s` (float64, (13,): bin edges, s; the last is inf, the
    /// activation's end), `after_dps` (float64, (n, 3, 12): per activation, axis and bin, the
    /// loop's 1-s residual's mean there less the activation's mean, °/s; NaN for a bin the
    /// activation ends before), `off_before_s` (float64, (n,); NaN when not recorded),
    /// `set_point_celsius` (float64, (n,)) — and `series_kind` (list of `protocol` / `field`).
    #[getter]
    fn profiles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let bins = PROFILE_EDGES_S.len() - 1;
        let after: Vec<f64> = self
            .profiles
            .iter()
            .flat_map(|p| p.after_dps.iter().flat_map(|axis| axis.iter().copied()))
            .collect();
        let after = Array3::from_shape_vec((self.profiles.len(), 3, bins), after)
            .map_err(|e| Error::Input(format!("internal: profile shape: {e}")))?;
        let dict = PyDict::new(py);
        dict.set_item("edges_s", vector(py, PROFILE_EDGES_S.to_vec()))?;
        dict.set_item("after_dps", after.into_pyarray(py))?;
        let of = |f: fn(&ProfileRow) -> f64| self.profiles.iter().map(f).collect::<Vec<f64>>();
        dict.set_item(
            "off_before_s",
            vector(py, of(|p| p.off_before_s.unwrap_or(f64::NAN))),
        )?;
        dict.set_item("set_point_celsius", vector(py, of(|p| p.set_point_celsius)))?;
        let kinds: Vec<&str> = self
            .profiles
            .iter()
            .map(|p| p.series_kind.as_str())
            .collect();
        dict.set_item("series_kind", kinds)?;
        Ok(dict)
    }

    /// How many activations played each part: calibration, training, held_out, outside_range,
    /// diagnosed.
    #[getter]
    fn activations(&self) -> Vec<(String, usize)> {
        self.counts.clone()
    }

    fn __repr__(&self) -> String {
        let chosen: Vec<String> = self
            .chosen
            .iter()
            .map(|(axis, name)| {
                format!(
                    "{axis}: {}",
                    name.as_deref().unwrap_or("nothing significant")
                )
            })
            .collect();
        format!("<Diagnosis {}: {}>", self.unit_id, chosen.join("; "))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        pickle_state::reduce(slf)
    }
}

impl Pickled for PyDiagnosis {
    const KIND: &'static str = "Diagnosis";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        pickle_state::encode(Self::KIND, self)
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        pickle_state::decode(Self::KIND, state)
    }
}

/// The rankings of `axes` as flat records.
fn records(axes: &[AxisDiagnosis; 3]) -> Vec<RankRecord<'_>> {
    axes.iter()
        .flat_map(|axis| {
            axis.ranking.iter().enumerate().map(|(i, c)| RankRecord {
                axis: axis.axis,
                rank: i + 1,
                candidate: &c.name,
                level: c.level,
                explained: c.explained,
                family_p_value: c.family_p_value,
                p_value: c.p_value,
                whole_p_value: c.whole_p_value,
                drift_p_value: c.drift_p_value,
                significant: c.significant,
                thermal_response: c.thermal_response,
                stable: c.stable,
                detectable_share: axis.detectable_share,
                size_threshold: if c.thermal_response {
                    axis.response_size_threshold
                } else {
                    axis.size_threshold
                },
                baseline_explained_within: axis.baseline_explained_within,
                baseline_explained_between: axis.baseline_explained_between,
                coefficient: c.coefficient,
                absorbed_by_model: c.absorbed_by_model,
            })
        })
        .collect()
}
