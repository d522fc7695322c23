//! `pickle` and `copy.deepcopy` of every class: `__reduce__` gives `(_restore, (kind, state))`.
//!
//! The models travel as their firmware image (versioned, checksummed, validated on the way back);
//! everything else as postcard bytes of its serde form. drift-fit's, drift-evaluate's and
//! drift-recording's result types are described here with serde's remote derive, field for field,
//! so those crates stay serde-free and a field added there fails to compile here instead of being
//! dropped silently. A state is for the same gyrodrift version (dask, multiprocessing, caches):
//! `_restore` refuses another version's bytes by name.

use std::collections::BTreeMap;
use std::sync::Arc;

use drift_core::{ModifiedTables, PolynomialTables, RecommendedTables, RelativePolynomialTables};
use drift_evaluate::evaluate::{ActivationResult, ModelKind, ModelResult};
use drift_evaluate::summary::Split;
use drift_fit::analyse::Analysed;
use drift_fit::curves::{AveragedCurve, CurveKey, SetPointCurves};
use drift_fit::history_order::Crossing;
use drift_fit::{FitSettings, FittedUnit};
use drift_recording::{AuxChannel, Segment, SegmentLabels, SeriesKind, TemperatureScale};
use pyo3::prelude::*;
use pyo3::PyClassInitializer;
use serde::{Deserialize, Serialize};

use crate::analysed::PyAnalysed;
use crate::corrector::{PyCorrector, PyOutput};
use crate::diagnosis::PyDiagnosis;
use crate::errors::Error;
use crate::evaluation::PyEvaluation;
use crate::extension::PyExtraTerm;
use crate::fit::PyFittedUnit;
use crate::fit_settings::PyFitSettings;
use crate::labels::PyLabels;
use crate::model_io;
use crate::pickle_state::{decode, encode, Pickled};
use crate::recording::PyRecording;
use crate::results::PyActivationResult;
use crate::segment::{PyAuxChannel, PySegment};
use crate::settings::PySettings;
use crate::stillness::PyStillnessLearner;
use crate::tables::{
    PyModifiedTables, PyPolynomialTables, PyRecommendedTables, PyRelativePolynomialTables,
};
use crate::uncertainty::PyUncertainty;

fn rebuild<T: Pickled + Into<PyClassInitializer<T>>>(
    py: Python<'_>,
    state: &[u8],
) -> PyResult<Py<PyAny>> {
    Ok(Py::new(py, T::restore(py, state)?)?.into_any())
}

/// Rebuilds a pickled gyrodrift object (what `__reduce__` names; not for direct use).
#[pyfunction]
#[pyo3(name = "_restore")]
pub fn restore(py: Python<'_>, kind: &str, version: &str, state: &[u8]) -> PyResult<Py<PyAny>> {
    let ours = env!("CARGO_PKG_VERSION");
    if version != ours {
        return Err(Error::Input(format!(
            "cannot unpickle a gyrodrift {kind} of version {version} with gyrodrift {ours}: pickles are for the same version; save models with save_image/save_json"
        ))
        .into());
    }
    match kind {
        PyModifiedTables::KIND => rebuild::<PyModifiedTables>(py, state),
        PyPolynomialTables::KIND => rebuild::<PyPolynomialTables>(py, state),
        PyRelativePolynomialTables::KIND => rebuild::<PyRelativePolynomialTables>(py, state),
        PyRecommendedTables::KIND => rebuild::<PyRecommendedTables>(py, state),
        PySettings::KIND => rebuild::<PySettings>(py, state),
        PyExtraTerm::KIND => rebuild::<PyExtraTerm>(py, state),
        PyFitSettings::KIND => rebuild::<PyFitSettings>(py, state),
        PyLabels::KIND => rebuild::<PyLabels>(py, state),
        PyOutput::KIND => rebuild::<PyOutput>(py, state),
        PyAuxChannel::KIND => rebuild::<PyAuxChannel>(py, state),
        PySegment::KIND => rebuild::<PySegment>(py, state),
        PyRecording::KIND => rebuild::<PyRecording>(py, state),
        PyAnalysed::KIND => rebuild::<PyAnalysed>(py, state),
        PyFittedUnit::KIND => rebuild::<PyFittedUnit>(py, state),
        PyActivationResult::KIND => rebuild::<PyActivationResult>(py, state),
        PyEvaluation::KIND => rebuild::<PyEvaluation>(py, state),
        PyDiagnosis::KIND => rebuild::<PyDiagnosis>(py, state),
        PyCorrector::KIND => rebuild::<PyCorrector>(py, state),
        PyStillnessLearner::KIND => rebuild::<PyStillnessLearner>(py, state),
        PyUncertainty::KIND => rebuild::<PyUncertainty>(py, state),
        _ => Err(Error::Input(format!("cannot unpickle unknown gyrodrift class {kind:?}")).into()),
    }
}

macro_rules! pickled_model {
    ($class:ty, $model:ty, $kind:literal) => {
        impl Pickled for $class {
            const KIND: &'static str = $kind;
            fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
                Ok(model_io::to_image(&*self.0)?)
            }
            fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
                Ok(Self(Arc::new(model_io::from_image::<$model>(state)?)))
            }
        }
    };
}

pickled_model!(PyModifiedTables, ModifiedTables, "ModifiedTables");
pickled_model!(PyPolynomialTables, PolynomialTables, "PolynomialTables");
pickled_model!(
    PyRelativePolynomialTables,
    RelativePolynomialTables,
    "RelativePolynomialTables"
);
pickled_model!(PyRecommendedTables, RecommendedTables, "RecommendedTables");

/// A newtype class over a serde type: its state is the inner value.
macro_rules! pickled_newtype {
    ($class:ident, $kind:literal) => {
        impl Pickled for $class {
            const KIND: &'static str = $kind;
            fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
                encode(Self::KIND, &self.0)
            }
            fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
                decode(Self::KIND, state).map($class)
            }
        }
    };
}

pickled_newtype!(PySettings, "Settings");
pickled_newtype!(PyExtraTerm, "ExtraTerm");
pickled_newtype!(PyFitSettings, "FitSettings");

impl Pickled for PyLabels {
    const KIND: &'static str = "Labels";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &LabelsState(self.0.clone()))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        decode::<LabelsState>(Self::KIND, state).map(|l| PyLabels(l.0))
    }
}

impl Pickled for PyOutput {
    const KIND: &'static str = "Output";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &(self.corrected_dps, self.bias_dps, self.flags))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let (corrected_dps, bias_dps, flags) = decode(Self::KIND, state)?;
        Ok(Self {
            corrected_dps,
            bias_dps,
            flags,
        })
    }
}

impl Pickled for PyAuxChannel {
    const KIND: &'static str = "AuxChannel";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &self.channel)
    }
    fn restore(py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        PyAuxChannel::wrap(py, decode::<AuxChannel>(Self::KIND, state)?)
    }
}

// serde's remote descriptions of the result types, field for field (the labels too: their own
// serde form skips a field when empty, which a non-self-describing format cannot read back).

#[derive(Serialize, Deserialize)]
#[serde(remote = "SegmentLabels")]
struct SegmentLabelsDef {
    unit_id: String,
    set_point_celsius: f64,
    session_set_point_celsius: Option<f64>,
    series_kind: SeriesKind,
    series: u32,
    repeat: u32,
    activation: u32,
    interval_min: Option<f64>,
    off_before_s: Option<f64>,
}

#[derive(Serialize, Deserialize)]
struct LabelsState(#[serde(with = "SegmentLabelsDef")] SegmentLabels);

#[derive(Serialize, Deserialize)]
#[serde(remote = "Segment")]
struct SegmentDef {
    #[serde(with = "SegmentLabelsDef")]
    labels: SegmentLabels,
    sample_rate_hz: u32,
    power_on_ns: u64,
    since_power_on: Vec<u32>,
    rate_dps: [Vec<f32>; 3],
    temperature_raw: [Vec<i16>; 3],
    aux: BTreeMap<String, AuxChannel>,
    temperature_scale: TemperatureScale,
}

#[derive(Serialize, Deserialize)]
struct SegmentState(#[serde(with = "SegmentDef")] Segment);

#[derive(Serialize, Deserialize)]
#[serde(remote = "Analysed")]
struct AnalysedDef {
    #[serde(with = "SegmentLabelsDef")]
    labels: SegmentLabels,
    grid_ms: u32,
    sample_rate_hz: u32,
    switch_on_raw: [f32; 3],
    switch_on_celsius: [f64; 3],
    initial_bias_dps: [f64; 3],
    drift_dps: [Vec<f32>; 3],
    rise_celsius: [Vec<f32>; 3],
    temperature_scale: TemperatureScale,
}

#[derive(Serialize, Deserialize)]
struct AnalysedState(#[serde(with = "AnalysedDef")] Analysed);

#[derive(Serialize, Deserialize)]
#[serde(remote = "CurveKey")]
enum CurveKeyDef {
    Independent,
    After { interval_s: u32, activation: u32 },
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "AveragedCurve")]
struct AveragedCurveDef {
    #[serde(with = "CurveKeyDef")]
    key: CurveKey,
    members: usize,
    drift_dps: [Vec<f64>; 3],
    rise_celsius: [Vec<f64>; 3],
    switch_on_celsius: [f64; 3],
    initial_bias_dps: [f64; 3],
}

#[derive(Serialize, Deserialize)]
struct AveragedCurveState(#[serde(with = "AveragedCurveDef")] AveragedCurve);

#[derive(Serialize, Deserialize)]
struct SetPointCurvesState {
    set_point_celsius: f64,
    grid_ms: u32,
    ambient_celsius: [f64; 3],
    initial_bias_dps: [f64; 3],
    curves: Vec<AveragedCurveState>,
}

#[derive(Serialize, Deserialize)]
struct CurveKeyState(#[serde(with = "CurveKeyDef")] CurveKey);

#[derive(Serialize, Deserialize)]
#[serde(remote = "Crossing")]
struct CrossingDef {
    set_point_celsius: f64,
    axis: usize,
    #[serde(with = "CurveKeyDef")]
    warmer: CurveKey,
    #[serde(with = "CurveKeyDef")]
    colder: CurveKey,
    switched_on_warmer_by_celsius: f64,
    at_ms: u32,
    rise_excess_celsius: f64,
    crossing_pairs: usize,
    compared_pairs: usize,
}

#[derive(Serialize, Deserialize)]
struct CrossingState(#[serde(with = "CrossingDef")] Crossing);

/// A fitted unit: the tables through serde (drift-core's own form), the rest described here.
#[derive(Serialize, Deserialize)]
struct FittedState {
    unit_id: String,
    modified: ModifiedTables,
    by_history: ModifiedTables,
    standard: PolynomialTables,
    third_order: PolynomialTables,
    relative: RelativePolynomialTables,
    relative_cubic: RelativePolynomialTables,
    recommended: RecommendedTables,
    set_points: Vec<SetPointCurvesState>,
    curve_keys: Vec<CurveKeyState>,
    notes: Vec<String>,
    crossings: Vec<CrossingState>,
    settings: FitSettings,
}

impl FittedState {
    fn of(unit: &FittedUnit, settings: &FitSettings) -> Self {
        let set_points = unit
            .set_points
            .iter()
            .map(|s| SetPointCurvesState {
                set_point_celsius: s.set_point_celsius,
                grid_ms: s.grid_ms,
                ambient_celsius: s.ambient_celsius,
                initial_bias_dps: s.initial_bias_dps,
                curves: s.curves.iter().cloned().map(AveragedCurveState).collect(),
            })
            .collect();
        Self {
            unit_id: unit.unit_id.clone(),
            modified: unit.modified.clone(),
            by_history: unit.by_history.clone(),
            standard: unit.standard.clone(),
            third_order: unit.third_order.clone(),
            relative: unit.relative.clone(),
            relative_cubic: unit.relative_cubic.clone(),
            recommended: unit.recommended.clone(),
            set_points,
            curve_keys: unit.curve_keys.iter().copied().map(CurveKeyState).collect(),
            notes: unit.notes.clone(),
            crossings: unit.crossings.iter().cloned().map(CrossingState).collect(),
            settings: settings.clone(),
        }
    }

    fn into_class(self) -> PyFittedUnit {
        let set_points = self
            .set_points
            .into_iter()
            .map(|s| SetPointCurves {
                set_point_celsius: s.set_point_celsius,
                grid_ms: s.grid_ms,
                ambient_celsius: s.ambient_celsius,
                initial_bias_dps: s.initial_bias_dps,
                curves: s.curves.into_iter().map(|c| c.0).collect(),
            })
            .collect();
        PyFittedUnit {
            unit: Arc::new(FittedUnit {
                unit_id: self.unit_id,
                modified: self.modified,
                by_history: self.by_history,
                standard: self.standard,
                third_order: self.third_order,
                relative: self.relative,
                relative_cubic: self.relative_cubic,
                recommended: self.recommended,
                set_points,
                curve_keys: self.curve_keys.into_iter().map(|k| k.0).collect(),
                notes: self.notes,
                crossings: self.crossings.into_iter().map(|c| c.0).collect(),
            }),
            settings: self.settings,
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "ModelKind")]
enum ModelKindDef {
    Uncorrected,
    Standard,
    ThirdOrder,
    Relative,
    RelativeCubic,
    Modified,
    ByHistory,
    Recommended,
    AtAmbient,
}

#[derive(Serialize, Deserialize)]
#[serde(remote = "ModelResult")]
struct ModelResultDef {
    #[serde(with = "ModelKindDef")]
    model: ModelKind,
    drift_dps: [f64; 3],
    residual_rms_dps: [f64; 3],
    flags: [u16; 3],
}

#[derive(Serialize, Deserialize)]
struct ModelResultState(#[serde(with = "ModelResultDef")] ModelResult);

#[derive(Serialize, Deserialize)]
#[serde(remote = "Split")]
enum SplitDef {
    Validation,
    HeldOutRepeat,
    Field,
    NoiseFloor,
}

/// One evaluated activation with its split.
#[derive(Serialize, Deserialize)]
struct ResultState {
    #[serde(with = "SplitDef")]
    split: Split,
    #[serde(with = "SegmentLabelsDef")]
    labels: SegmentLabels,
    models: Vec<ModelResultState>,
}

impl ResultState {
    fn of(split: Split, result: &ActivationResult) -> Self {
        Self {
            split,
            labels: result.labels.clone(),
            models: result
                .models
                .iter()
                .cloned()
                .map(ModelResultState)
                .collect(),
        }
    }

    fn into_parts(self) -> (Split, ActivationResult) {
        let result = ActivationResult {
            labels: self.labels,
            models: self.models.into_iter().map(|m| m.0).collect(),
        };
        (self.split, result)
    }
}

impl Pickled for PySegment {
    const KIND: &'static str = "Segment";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &SegmentState(Segment::clone(&self.segment)))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        decode::<SegmentState>(Self::KIND, state).map(|s| PySegment::wrap(s.0))
    }
}

impl Pickled for PyAnalysed {
    const KIND: &'static str = "AnalysedActivation";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &AnalysedState(self.analysed.clone()))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        decode::<AnalysedState>(Self::KIND, state).map(|a| PyAnalysed::wrap(a.0))
    }
}

impl Pickled for PyFittedUnit {
    const KIND: &'static str = "FittedUnit";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &FittedState::of(&self.unit, &self.settings))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        decode::<FittedState>(Self::KIND, state).map(FittedState::into_class)
    }
}

impl Pickled for PyActivationResult {
    const KIND: &'static str = "ActivationResult";
    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        encode(Self::KIND, &ResultState::of(self.split, &self.result))
    }
    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let (split, result) = decode::<ResultState>(Self::KIND, state)?.into_parts();
        Ok(Self { split, result })
    }
}

/// A recording in memory: its segments by value.
#[derive(Serialize, Deserialize)]
struct RecordingState {
    path: Option<std::path::PathBuf>,
    metadata: BTreeMap<String, String>,
    unit_id: String,
    sample_rate_hz: u32,
    segments: Vec<SegmentState>,
}

impl Pickled for PyRecording {
    const KIND: &'static str = "Recording";
    fn state(&self, py: Python<'_>) -> PyResult<Vec<u8>> {
        let state = RecordingState {
            path: self.path.clone(),
            metadata: self.metadata.clone(),
            unit_id: self.unit_id.clone(),
            sample_rate_hz: self.sample_rate_hz,
            segments: self
                .segment_arcs(py)
                .iter()
                .map(|s| SegmentState(Segment::clone(s)))
                .collect(),
        };
        encode(Self::KIND, &state)
    }
    fn restore(py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let state: RecordingState = decode(Self::KIND, state)?;
        let segments = state
            .segments
            .into_iter()
            .map(|s| Py::new(py, PySegment::wrap(s.0)))
            .collect::<PyResult<_>>()?;
        Ok(PyRecording {
            path: state.path,
            metadata: state.metadata,
            unit_id: state.unit_id,
            sample_rate_hz: state.sample_rate_hz,
            segments,
        })
    }
}

/// An evaluation: fitted units, analysed calibration activations, results, by value.
#[derive(Serialize, Deserialize)]
struct EvaluationState {
    fitted: Vec<FittedState>,
    calibration: Vec<AnalysedState>,
    results: Vec<ResultState>,
    noise_floor_units: Vec<String>,
    timings: Vec<(String, f64)>,
}

impl Pickled for PyEvaluation {
    const KIND: &'static str = "Evaluation";
    fn state(&self, py: Python<'_>) -> PyResult<Vec<u8>> {
        let state = EvaluationState {
            fitted: self
                .fitted
                .iter()
                .map(|f| {
                    let f = f.bind(py).get();
                    FittedState::of(&f.unit, &f.settings)
                })
                .collect(),
            calibration: self
                .calibration
                .iter()
                .map(|a| AnalysedState(a.bind(py).get().analysed.clone()))
                .collect(),
            results: self
                .results
                .iter()
                .map(|(split, result)| ResultState::of(*split, result))
                .collect(),
            noise_floor_units: self.noise_floor_units.clone(),
            timings: self.timings.clone(),
        };
        encode(Self::KIND, &state)
    }
    fn restore(py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let state: EvaluationState = decode(Self::KIND, state)?;
        let fitted = state
            .fitted
            .into_iter()
            .map(|f| Py::new(py, f.into_class()))
            .collect::<PyResult<_>>()?;
        let calibration = state
            .calibration
            .into_iter()
            .map(|a| Py::new(py, PyAnalysed::wrap(a.0)))
            .collect::<PyResult<_>>()?;
        Ok(PyEvaluation {
            fitted,
            calibration,
            results: state
                .results
                .into_iter()
                .map(ResultState::into_parts)
                .collect(),
            noise_floor_units: state.noise_floor_units,
            timings: state.timings,
        })
    }
}
