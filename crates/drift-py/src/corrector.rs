//! `gyrodrift.Corrector`: a model plus one unit's run-time state, correcting one sample at a time
//! or whole numpy arrays. Every sample goes through drift-core: `CorrectorState::correct` (one at a
//! time) or `correct_block` (arrays; the same bits), or `CorrectorState::correct_with_aux` when the
//! caller passes auxiliary inputs: the code the firmware runs.

use std::sync::Arc;

use drift_core::{
    AxisModel, CorrectorState, Flags, Model, ModifiedTables, Output, PolynomialTables, Previous,
    RecommendedTables, RelativePolynomialTables, Sample, AUX_INPUTS,
};
use numpy::ndarray::{Array2, ArrayView1};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

use crate::args;
use crate::arrays::{
    copy_times, describe, rows_per_axis, times, BatchArrays, OutArrays, Rows, RowsView,
};
use crate::errors::Error;
use crate::model_io;
use crate::tables::{
    PyModifiedTables, PyPolynomialTables, PyRecommendedTables, PyRelativePolynomialTables,
};

/// Samples staged at a time between the caller's arrays and the corrector (on the stack).
const BLOCK: usize = 512;

/// Values in `BLOCK` rows of an `(n, 3)` output array.
const BLOCK_VALUES: usize = BLOCK * 3;

/// A model and its state; the model kind decides the state type.
#[derive(Clone, Debug)]
enum Engine {
    Modified(
        Arc<ModifiedTables>,
        CorrectorState<<ModifiedAxis as AxisModel>::State>,
    ),
    Polynomial(
        Arc<PolynomialTables>,
        CorrectorState<<PolynomialAxis as AxisModel>::State>,
    ),
    Relative(
        Arc<RelativePolynomialTables>,
        CorrectorState<<RelativeAxis as AxisModel>::State>,
    ),
    Recommended(
        Arc<RecommendedTables>,
        CorrectorState<<RecommendedAxis as AxisModel>::State>,
    ),
}

type ModifiedAxis = <ModifiedTables as Model>::Axis;
type PolynomialAxis = <PolynomialTables as Model>::Axis;
type RelativeAxis = <RelativePolynomialTables as Model>::Axis;
type RecommendedAxis = <RecommendedTables as Model>::Axis;

/// The batch's inputs, borrowed from the caller's arrays (no Python object inside, so they can be
/// used without the GIL).
struct Batch<'a> {
    times: ArrayView1<'a, u32>,
    rates: RowsView<'a>,
    temperatures: RowsView<'a>,
    /// `(n, AUX_INPUTS)` auxiliary inputs, if the caller passed them.
    aux: Option<RowsView<'a>>,
}

/// Where the batch's outputs go: `n × 3` row-major slices (new vectors or the caller's arrays).
struct Corrected<'a> {
    corrected_dps: &'a mut [f32],
    bias_dps: &'a mut [f32],
    flags: &'a mut [u16],
}

/// One sample through drift-core: `correct_with_aux` with auxiliary inputs, else `correct`.
fn correct_one<M, S>(
    model: &M,
    state: &mut CorrectorState<S>,
    sample: &Sample,
    aux: Option<&[f32; AUX_INPUTS]>,
) -> Output
where
    M: Model,
    M::Axis: AxisModel<State = S>,
    S: Copy + Default,
{
    match aux {
        Some(aux) => state.correct_with_aux(model, sample, aux),
        None => state.correct(model, sample),
    }
}

/// The batch through drift-core, staged [`BLOCK`] samples at a time: `correct_block` without
/// auxiliary inputs (drift-core's block path: the polynomial baselines evaluate many samples at
/// once), `correct_with_aux` per sample with them.
fn correct_all<M, S>(
    model: &M,
    state: &mut CorrectorState<S>,
    batch: &Batch<'_>,
    out: Corrected<'_>,
) where
    M: Model,
    M::Axis: AxisModel<State = S>,
    S: Copy + Default,
{
    let n = batch.times.len();
    let mut staged = [Sample::default(); BLOCK];
    let mut staged_aux = [[0.0_f32; AUX_INPUTS]; BLOCK];
    let mut corrected = [Output::default(); BLOCK];
    let rows = out
        .corrected_dps
        .chunks_mut(BLOCK_VALUES)
        .zip(out.bias_dps.chunks_mut(BLOCK_VALUES))
        .zip(out.flags.chunks_mut(BLOCK_VALUES));
    for (start, ((corrected_rows, bias_rows), flags_rows)) in (0..n).step_by(BLOCK).zip(rows) {
        let count = BLOCK.min(n.saturating_sub(start));
        let block = staged.get_mut(..count).unwrap_or_default();
        copy_times(
            &batch.times,
            start,
            block.iter_mut().map(|s| &mut s.since_power_on_ms),
        );
        batch
            .rates
            .copy_rows(start, block.iter_mut().map(|s| &mut s.rate_dps));
        batch
            .temperatures
            .copy_rows(start, block.iter_mut().map(|s| &mut s.temperature_raw));
        let outputs = corrected.get_mut(..count).unwrap_or_default();
        match &batch.aux {
            None => {
                state.correct_block(model, block, outputs);
            }
            Some(aux) => {
                let aux_block = staged_aux.get_mut(..count).unwrap_or_default();
                aux.copy_rows(start, aux_block.iter_mut());
                for ((sample, aux), output) in
                    block.iter().zip(aux_block.iter()).zip(outputs.iter_mut())
                {
                    *output = state.correct_with_aux(model, sample, aux);
                }
            }
        }
        let destinations = corrected_rows
            .chunks_exact_mut(3)
            .zip(bias_rows.chunks_exact_mut(3))
            .zip(flags_rows.chunks_exact_mut(3));
        for (output, ((corrected, bias), flags)) in outputs.iter().zip(destinations) {
            for (dst, src) in corrected.iter_mut().zip(output.corrected_dps) {
                *dst = src;
            }
            for (dst, src) in bias.iter_mut().zip(output.bias_dps) {
                *dst = src;
            }
            for (dst, src) in flags.iter_mut().zip(output.flags) {
                *dst = src.0;
            }
        }
    }
}

/// One of the corrector's switch-ons, by what is given: what was kept, a measured ambient.
fn start<M>(
    state: &mut CorrectorState<<M::Axis as AxisModel>::State>,
    model: &M,
    raw: [f32; 3],
    previous: Option<&mut [Previous; 3]>,
    ambient_celsius: Option<f32>,
) -> Result<[Flags; 3], drift_core::Error>
where
    M: Model,
{
    match (previous, ambient_celsius) {
        (None, None) => state.power_on(model, raw),
        (Some(kept), None) => state.power_on_after(model, raw, kept),
        (None, Some(ambient)) => state.power_on_at_ambient(model, raw, ambient),
        (Some(kept), Some(ambient)) => state.power_on_after_at_ambient(model, raw, ambient, kept),
    }
}

impl Engine {
    fn power_on(
        &mut self,
        raw: [f32; 3],
        previous: Option<&mut [Previous; 3]>,
        ambient_celsius: Option<f32>,
    ) -> Result<[Flags; 3], drift_core::Error> {
        match self {
            Self::Modified(model, state) => start(state, &**model, raw, previous, ambient_celsius),
            Self::Polynomial(model, state) => {
                start(state, &**model, raw, previous, ambient_celsius)
            }
            Self::Relative(model, state) => start(state, &**model, raw, previous, ambient_celsius),
            Self::Recommended(model, state) => {
                start(state, &**model, raw, previous, ambient_celsius)
            }
        }
    }

    fn keep(&self, previous: &mut [Previous; 3]) {
        match self {
            Self::Modified(model, state) => state.keep(&**model, previous),
            Self::Polynomial(model, state) => state.keep(&**model, previous),
            Self::Relative(model, state) => state.keep(&**model, previous),
            Self::Recommended(model, state) => state.keep(&**model, previous),
        }
    }

    fn settings(&self) -> &drift_core::Settings {
        match self {
            Self::Modified(model, _) => model.settings(),
            Self::Polynomial(model, _) => model.settings(),
            Self::Relative(model, _) => model.settings(),
            Self::Recommended(model, _) => model.settings(),
        }
    }

    fn power_off(&mut self) {
        match self {
            Self::Modified(_, state) => state.power_off(),
            Self::Polynomial(_, state) => state.power_off(),
            Self::Relative(_, state) => state.power_off(),
            Self::Recommended(_, state) => state.power_off(),
        }
    }

    fn correct(&mut self, sample: &Sample, aux: Option<&[f32; AUX_INPUTS]>) -> Output {
        match self {
            Self::Modified(model, state) => correct_one(&**model, state, sample, aux),
            Self::Polynomial(model, state) => correct_one(&**model, state, sample, aux),
            Self::Relative(model, state) => correct_one(&**model, state, sample, aux),
            Self::Recommended(model, state) => correct_one(&**model, state, sample, aux),
        }
    }

    fn correct_all(&mut self, batch: &Batch<'_>, out: Corrected<'_>) {
        match self {
            Self::Modified(model, state) => correct_all(&**model, state, batch, out),
            Self::Polynomial(model, state) => correct_all(&**model, state, batch, out),
            Self::Relative(model, state) => correct_all(&**model, state, batch, out),
            Self::Recommended(model, state) => correct_all(&**model, state, batch, out),
        }
    }

    fn is_powered_on(&self) -> bool {
        match self {
            Self::Modified(_, state) => state.is_powered_on(),
            Self::Polynomial(_, state) => state.is_powered_on(),
            Self::Relative(_, state) => state.is_powered_on(),
            Self::Recommended(_, state) => state.is_powered_on(),
        }
    }

    /// Per axis: (raw reading at switch-on, initial bias °/s).
    fn switch_on(&self) -> [(f32, f32); 3] {
        match self {
            Self::Modified(_, state) => state
                .axes()
                .map(|axis| (axis.switch_on_raw(), axis.initial_bias_dps())),
            Self::Polynomial(_, state) => state
                .axes()
                .map(|axis| (axis.switch_on_raw(), axis.initial_bias_dps())),
            Self::Relative(_, state) => state
                .axes()
                .map(|axis| (axis.switch_on_raw(), axis.initial_bias_dps())),
            Self::Recommended(_, state) => state
                .axes()
                .map(|axis| (axis.switch_on_raw(), axis.initial_bias_dps())),
        }
    }
}

/// One corrected sample: per axis X, Y, Z.
#[pyclass(module = "gyrodrift", name = "Output", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyOutput {
    /// Rate with the estimated drift removed, °/s.
    #[pyo3(get)]
    pub(crate) corrected_dps: (f32, f32, f32),
    /// Estimated bias that was removed (initial bias + drift since switch-on), °/s.
    #[pyo3(get)]
    pub(crate) bias_dps: (f32, f32, f32),
    /// Status flags (see `gyrodrift.Flags`).
    #[pyo3(get)]
    pub(crate) flags: (u16, u16, u16),
}

#[pymethods]
impl PyOutput {
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        format!(
            "Output(corrected_dps={:?}, bias_dps={:?}, flags={:?})",
            self.corrected_dps, self.bias_dps, self.flags
        )
    }
}

/// Raw readings this close to 0 that read as outside the calibrated range are taken for °C.
const CELSIUS_LIKE_RAW: f32 = 150.0;

/// Refuses a switch-on whose raw readings look like °C: every axis within ±150 of zero (a °C
/// value, not a count at 200 raw/°C) and outside the model's calibrated temperatures. Checked on
/// a trial start, so a refusal leaves the state unchanged.
fn refuse_celsius(
    raw: [f32; 3],
    flags: [Flags; 3],
    settings: &drift_core::Settings,
) -> Result<(), Error> {
    let outside = |f: &Flags| {
        f.contains(Flags::AMBIENT_OUT_OF_RANGE) || f.contains(Flags::TEMPERATURE_OUT_OF_RANGE)
    };
    if raw.iter().all(|r| r.abs() <= CELSIUS_LIKE_RAW) && flags.iter().all(outside) {
        let celsius = raw.map(|r| settings.celsius(r));
        return Err(Error::Input(format!(
            "`switch_on_raw` {raw:?} reads as {celsius:?} °C, outside the model's calibrated temperatures: these look like °C, not raw sensor counts ({} raw/°C); convert with model.settings.raw(celsius); the state is unchanged",
            settings.raw_per_celsius
        )));
    }
    Ok(())
}

/// A refused switch-on's message: the input the corrector named.
fn refused(raw: [f32; 3], ambient_celsius: Option<f32>, error: drift_core::Error) -> Error {
    match ambient_celsius {
        Some(ambient) if error.field == "ambient_celsius" => Error::Input(format!(
            "`ambient_celsius` must be finite, got {ambient} ({error}); the state is unchanged"
        )),
        _ => Error::Input(format!(
            "`switch_on_raw` must be finite on every axis, got {raw:?} ({error}); the state is unchanged"
        )),
    }
}

fn triple<T: Copy>(values: [T; 3]) -> (T, T, T) {
    let [x, y, z] = values;
    (x, y, z)
}

/// Corrects a gyro's temperature drift: a model (the paper's tables or a polynomial baseline) and
/// one unit's run-time state.
#[pyclass(module = "gyrodrift", name = "Corrector")]
#[derive(Debug)]
pub struct PyCorrector {
    engine: Engine,
}

/// `OutArrays` checked contiguity already; this names the argument should that ever change.
fn not_contiguous(error: numpy::AsSliceError) -> Error {
    Error::Input(format!("`out` arrays must be C-contiguous: {error}"))
}

/// `power_on_after`'s result: the activation's flags per axis and what to keep now, `(3, 2)`.
type Started<'py> = ((u16, u16, u16), Bound<'py, PyArray2<f32>>);

/// What the error messages call a kept previous activation.
const PREVIOUS_SHAPE: &str =
    "a float32 or float64 array of shape (3, 2): per axis X, Y, Z, [ambient °C, switch-off °C]";

/// A `(3, 2)` float array (or nested sequence) of what was kept of the previous activation, as
/// drift-core takes it (float64 rounded to f32 per value, as `astype(np.float32)` does).
pub(crate) fn previous_arg(name: &str, value: &Bound<'_, PyAny>) -> Result<[Previous; 3], Error> {
    let values = rows_per_axis(name, PREVIOUS_SHAPE, value)?;
    #[allow(clippy::cast_possible_truncation)]
    Ok(values.map(|[ambient, off]| Previous {
        ambient_celsius: ambient as f32,
        switch_off_celsius: off as f32,
    }))
}

/// `previous` as a new `(3, 2)` float32 array.
fn previous_array<'py>(
    py: Python<'py>,
    previous: &[Previous; 3],
) -> Result<Bound<'py, PyArray2<f32>>, Error> {
    let values = previous
        .iter()
        .flat_map(|p| [p.ambient_celsius, p.switch_off_celsius])
        .collect();
    Array2::from_shape_vec((3, 2), values)
        .map(|array| array.into_pyarray(py))
        .map_err(|error| Error::Input(format!("internal: previous shape (3, 2): {error}")))
}

fn to_array<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    rows: usize,
) -> Result<Bound<'py, PyArray2<T>>, Error> {
    Array2::from_shape_vec((rows, 3), values)
        .map(|array| array.into_pyarray(py))
        .map_err(|error| Error::Input(format!("internal: output shape ({rows}, 3): {error}")))
}

#[pymethods]
impl PyCorrector {
    /// A corrector for `model` (`ModifiedTables`, `PolynomialTables`, `RelativePolynomialTables`
    /// or `RecommendedTables`), not yet powered on.
    #[new]
    fn new(model: &Bound<'_, PyAny>) -> Result<Self, Error> {
        let engine = if let Ok(tables) = model.cast::<PyModifiedTables>() {
            Engine::Modified(Arc::clone(&tables.get().0), CorrectorState::new())
        } else if let Ok(tables) = model.cast::<PyPolynomialTables>() {
            Engine::Polynomial(Arc::clone(&tables.get().0), CorrectorState::new())
        } else if let Ok(tables) = model.cast::<PyRelativePolynomialTables>() {
            Engine::Relative(Arc::clone(&tables.get().0), CorrectorState::new())
        } else if let Ok(tables) = model.cast::<PyRecommendedTables>() {
            Engine::Recommended(Arc::clone(&tables.get().0), CorrectorState::new())
        } else {
            return Err(Error::Input(format!(
                "`model` must be a gyrodrift.ModifiedTables, PolynomialTables, \
                 RelativePolynomialTables or RecommendedTables, got {}",
                describe(model)
            )));
        };
        Ok(Self { engine })
    }

    /// The model in use.
    #[getter]
    fn model(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        Ok(match &self.engine {
            Engine::Modified(model, _) => {
                Py::new(py, PyModifiedTables(Arc::clone(model)))?.into_any()
            }
            Engine::Polynomial(model, _) => {
                Py::new(py, PyPolynomialTables(Arc::clone(model)))?.into_any()
            }
            Engine::Relative(model, _) => {
                Py::new(py, PyRelativePolynomialTables(Arc::clone(model)))?.into_any()
            }
            Engine::Recommended(model, _) => {
                Py::new(py, PyRecommendedTables(Arc::clone(model)))?.into_any()
            }
        })
    }

    /// Whether `power_on` has succeeded since the last `power_off`.
    #[getter]
    fn is_powered_on(&self) -> bool {
        self.engine.is_powered_on()
    }

    /// Raw temperature readings at the last switch-on, per axis.
    #[getter]
    fn switch_on_raw(&self) -> (f32, f32, f32) {
        triple(self.engine.switch_on().map(|(raw, _)| raw))
    }

    /// Initial (switch-on) bias located at the last switch-on, per axis, °/s.
    #[getter]
    fn initial_bias_dps(&self) -> (f32, f32, f32) {
        triple(self.engine.switch_on().map(|(_, bias)| bias))
    }

    /// Starts an activation from the raw temperature readings at switch-on (X, Y, Z); returns the
    /// flags that hold for the whole activation, per axis. With `ambient_celsius` (the ambient the
    /// instrument measured, °C) the paper's stage 2 and initial bias are read there, not at the
    /// switch-on temperature (drift-core's `power_on_at_ambient`).
    #[pyo3(signature = (switch_on_raw, *, ambient_celsius = None))]
    fn power_on(
        &mut self,
        switch_on_raw: &Bound<'_, PyAny>,
        ambient_celsius: Option<f32>,
    ) -> Result<(u16, u16, u16), Error> {
        let raw = args::per_axis("switch_on_raw", switch_on_raw)?;
        let mut trial = self.engine.clone();
        let flags = trial
            .power_on(raw, None, ambient_celsius)
            .map_err(|error| refused(raw, ambient_celsius, error))?;
        refuse_celsius(raw, flags, trial.settings())?;
        self.engine = trial;
        Ok(triple(flags.map(|f| f.0)))
    }

    /// `power_on` with what was kept of the previous activation (`previous`, `(3, 2)`: per axis
    /// `[ambient °C, switch-off °C]`; all NaN when nothing was kept): a table keyed by heating
    /// history reads the activation's ambient and residual heat from it, other models ignore it.
    /// Returns the activation's flags and what to keep now (a new float32 `(3, 2)` array: this
    /// activation's ambient, switch-off NaN until `keep`); `previous` itself is not modified.
    /// With `ambient_celsius`, as `power_on`'s: the measured ambient replaces the estimate and is
    /// kept.
    #[pyo3(signature = (switch_on_raw, previous, *, ambient_celsius = None))]
    fn power_on_after<'py>(
        &mut self,
        py: Python<'py>,
        switch_on_raw: &Bound<'py, PyAny>,
        previous: &Bound<'py, PyAny>,
        ambient_celsius: Option<f32>,
    ) -> Result<Started<'py>, Error> {
        let raw = args::per_axis("switch_on_raw", switch_on_raw)?;
        let mut kept = previous_arg("previous", previous)?;
        let mut trial = self.engine.clone();
        let flags = trial
            .power_on(raw, Some(&mut kept), ambient_celsius)
            .map_err(|error| refused(raw, ambient_celsius, error))?;
        refuse_celsius(raw, flags, trial.settings())?;
        self.engine = trial;
        Ok((triple(flags.map(|f| f.0)), previous_array(py, &kept)?))
    }

    /// `previous` (`(3, 2)`, as `power_on_after` returned it) with this activation's last good
    /// temperature per axis recorded as its switch-off temperature, as a new float32 `(3, 2)`
    /// array; unchanged while not powered on. `previous` itself is not modified.
    fn keep<'py>(
        &self,
        py: Python<'py>,
        previous: &Bound<'py, PyAny>,
    ) -> Result<Bound<'py, PyArray2<f32>>, Error> {
        let mut kept = previous_arg("previous", previous)?;
        self.engine.keep(&mut kept);
        previous_array(py, &kept)
    }

    /// Ends the activation: samples pass through, flagged NOT_POWERED_ON, until the next power_on.
    fn power_off(&mut self) {
        self.engine.power_off();
    }

    /// Corrects one sample; `aux`: the auxiliary inputs an extended model's extra terms read
    /// (drift-core's `correct_with_aux`), or `None` (drift-core's `correct`).
    #[pyo3(signature = (since_power_on_ms, rate_dps, temperature_raw, *, aux = None))]
    fn correct(
        &mut self,
        since_power_on_ms: &Bound<'_, PyAny>,
        rate_dps: &Bound<'_, PyAny>,
        temperature_raw: &Bound<'_, PyAny>,
        aux: Option<&Bound<'_, PyAny>>,
    ) -> Result<PyOutput, Error> {
        let sample = Sample {
            since_power_on_ms: args::milliseconds("since_power_on_ms", since_power_on_ms)?,
            rate_dps: args::per_axis("rate_dps", rate_dps)?,
            temperature_raw: args::per_axis("temperature_raw", temperature_raw)?,
        };
        let aux = match aux {
            Some(aux) if !aux.is_none() => Some(args::aux_inputs("aux", aux)?),
            _ => None,
        };
        let output = self.engine.correct(&sample, aux.as_ref());
        Ok(PyOutput {
            corrected_dps: triple(output.corrected_dps),
            bias_dps: triple(output.bias_dps),
            flags: triple(output.flags.map(|f| f.0)),
        })
    }

    /// Corrects n samples in order, continuing the current activation; the GIL is released while
    /// the samples are corrected. `aux`: `(n, AUX_INPUTS)` auxiliary inputs (`correct_with_aux`
    /// per sample) or `None` (`correct`). With `out`, writes into the caller's arrays and returns
    /// them.
    #[pyo3(signature = (since_power_on_ms, rate_dps, temperature_raw, *, aux = None, out = None))]
    fn correct_batch<'py>(
        &mut self,
        py: Python<'py>,
        since_power_on_ms: &Bound<'py, PyAny>,
        rate_dps: &Bound<'py, PyAny>,
        temperature_raw: &Bound<'py, PyAny>,
        aux: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> Result<BatchArrays<'py>, Error> {
        let times_array = times("since_power_on_ms", since_power_on_ms)?;
        let rates = Rows::borrow("rate_dps", rate_dps)?;
        let temperatures = Rows::borrow_temperatures("temperature_raw", temperature_raw)?;
        let aux = match aux {
            Some(aux) if !aux.is_none() => Some(Rows::borrow_columns("aux", aux, AUX_INPUTS)?),
            _ => None,
        };
        let batch = Batch {
            times: times_array.as_array(),
            rates: rates.view(),
            temperatures: temperatures.view(),
            aux: aux.as_ref().map(Rows::view),
        };
        let n = batch.times.len();
        let aux_rows = batch.aux.as_ref().map(|aux| ("aux", aux.len()));
        for (name, rows) in [
            ("rate_dps", batch.rates.len()),
            ("temperature_raw", batch.temperatures.len()),
        ]
        .into_iter()
        .chain(aux_rows)
        {
            if rows != n {
                return Err(Error::Input(format!(
                    "`{name}` must have one row per time in `since_power_on_ms` ({n}), got {rows} rows"
                )));
            }
        }
        let engine = &mut self.engine;
        if let Some(out) = out {
            let OutArrays {
                arrays,
                mut corrected,
                mut bias,
                mut flags,
            } = OutArrays::borrow(out, n)?;
            let slices = Corrected {
                corrected_dps: corrected.as_slice_mut().map_err(not_contiguous)?,
                bias_dps: bias.as_slice_mut().map_err(not_contiguous)?,
                flags: flags.as_slice_mut().map_err(not_contiguous)?,
            };
            py.detach(|| engine.correct_all(&batch, slices));
            return Ok(arrays);
        }
        let len = n.saturating_mul(3);
        let (mut corrected, mut bias, mut flags) = (vec![0.0; len], vec![0.0; len], vec![0; len]);
        py.detach(|| {
            engine.correct_all(
                &batch,
                Corrected {
                    corrected_dps: &mut corrected,
                    bias_dps: &mut bias,
                    flags: &mut flags,
                },
            );
        });
        Ok((
            to_array(py, corrected, n)?,
            to_array(py, bias, n)?,
            to_array(py, flags, n)?,
        ))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let model = match &self.engine {
            Engine::Modified(..) => "ModifiedTables",
            Engine::Polynomial(..) => "PolynomialTables",
            Engine::Relative(..) => "RelativePolynomialTables",
            Engine::Recommended(..) => "RecommendedTables",
        };
        let state = if self.engine.is_powered_on() {
            "powered on"
        } else {
            "not powered on"
        };
        format!("<Corrector {model}, {state}>")
    }
}

/// A corrector's pickled form: the model as its firmware image and the run-time state, so that an
/// activation continues where it was (a worker process, a checkpoint).
#[derive(serde::Serialize, serde::Deserialize)]
enum EngineState {
    Modified(Vec<u8>, CorrectorState<<ModifiedAxis as AxisModel>::State>),
    Polynomial(
        Vec<u8>,
        CorrectorState<<PolynomialAxis as AxisModel>::State>,
    ),
    Relative(Vec<u8>, CorrectorState<<RelativeAxis as AxisModel>::State>),
    Recommended(
        Vec<u8>,
        CorrectorState<<RecommendedAxis as AxisModel>::State>,
    ),
}

impl crate::pickle_state::Pickled for PyCorrector {
    const KIND: &'static str = "Corrector";

    fn state(&self, _py: Python<'_>) -> PyResult<Vec<u8>> {
        let state = match &self.engine {
            Engine::Modified(m, s) => EngineState::Modified(model_io::to_image(&**m)?, *s),
            Engine::Polynomial(m, s) => EngineState::Polynomial(model_io::to_image(&**m)?, *s),
            Engine::Relative(m, s) => EngineState::Relative(model_io::to_image(&**m)?, *s),
            Engine::Recommended(m, s) => EngineState::Recommended(model_io::to_image(&**m)?, *s),
        };
        crate::pickle_state::encode(Self::KIND, &state)
    }

    fn restore(_py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let engine = match crate::pickle_state::decode(Self::KIND, state)? {
            EngineState::Modified(image, s) => {
                Engine::Modified(Arc::new(model_io::from_image(&image)?), s)
            }
            EngineState::Polynomial(image, s) => {
                Engine::Polynomial(Arc::new(model_io::from_image(&image)?), s)
            }
            EngineState::Relative(image, s) => {
                Engine::Relative(Arc::new(model_io::from_image(&image)?), s)
            }
            EngineState::Recommended(image, s) => {
                Engine::Recommended(Arc::new(model_io::from_image(&image)?), s)
            }
        };
        Ok(Self { engine })
    }
}
