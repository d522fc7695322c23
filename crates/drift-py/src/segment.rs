//! `gyrodrift.Segment` (one activation: rates, raw temperatures, auxiliary channels, labels) and
//! `gyrodrift.AuxChannel`. A segment holds drift-recording's `Segment`; its numpy arrays are made
//! on first access and kept (read-only).

use std::collections::BTreeMap;
use std::sync::Arc;

use drift_recording::{AuxChannel, Segment};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple};

use crate::args;
use crate::arrays::{describe, finite_values, raw_rows, Rows};
use crate::errors::Error;
use crate::labels::PyLabels;
use crate::outputs::{columns, read_only, vector};

/// A sample rate the recording format can store: a multiple of 100 Hz (the auxiliary rate) that
/// divides 10⁹ (so sample times are whole nanoseconds).
pub fn check_sample_rate(name: &str, value: &Bound<'_, PyAny>) -> Result<u32, Error> {
    const EXPECTED: &str = "a multiple of 100 Hz that divides 10**9 (e.g. 1000)";
    let rate: u32 = args::value(name, EXPECTED, value)?;
    if rate == 0 || rate % 100 != 0 || 1_000_000_000 % rate != 0 {
        return Err(Error::Input(format!(
            "`{name}` must be {EXPECTED}, got {rate}"
        )));
    }
    Ok(rate)
}

/// An auxiliary channel of one activation at its own rate.
#[pyclass(module = "gyrodrift", name = "AuxChannel", frozen)]
#[derive(Debug)]
pub struct PyAuxChannel {
    pub channel: AuxChannel,
    values: Py<PyArray1<f32>>,
}

impl PyAuxChannel {
    /// Wraps a channel, making its read-only values array.
    pub fn wrap(py: Python<'_>, channel: AuxChannel) -> PyResult<Self> {
        let values = read_only(vector(py, channel.values.clone()))?.unbind();
        Ok(Self { channel, values })
    }
}

#[pymethods]
impl PyAuxChannel {
    /// A channel: finite float32/float64 values (n,), a unit (e.g. "g", "V") and a rate in Hz.
    #[new]
    fn new(
        py: Python<'_>,
        values: &Bound<'_, PyAny>,
        unit: &Bound<'_, PyAny>,
        sample_rate_hz: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let channel = AuxChannel {
            values: finite_values("values", values)?,
            unit: args::text("unit", unit)?,
            sample_rate_hz: args::value(
                "sample_rate_hz",
                "an integer in 1..=4294967295",
                sample_rate_hz,
            )
            .and_then(|rate: u32| {
                if rate == 0 {
                    Err(Error::Input(
                        "`sample_rate_hz` must be an integer in 1..=4294967295, got 0".into(),
                    ))
                } else {
                    Ok(rate)
                }
            })?,
        };
        Self::wrap(py, channel)
    }

    /// Samples (read-only float32); sample k is at k / sample_rate_hz s after switch-on.
    #[getter]
    fn values(&self, py: Python<'_>) -> Py<PyArray1<f32>> {
        self.values.clone_ref(py)
    }

    /// Physical unit.
    #[getter]
    fn unit(&self) -> &str {
        &self.channel.unit
    }

    /// Sample rate, Hz.
    #[getter]
    fn sample_rate_hz(&self) -> u32 {
        self.channel.sample_rate_hz
    }

    fn __len__(&self) -> usize {
        self.channel.values.len()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        format!(
            "<AuxChannel {} values, {} Hz, {:?}>",
            self.channel.values.len(),
            self.channel.sample_rate_hz,
            self.channel.unit
        )
    }
}

/// Numpy views of a segment, made on first access.
struct Arrays {
    rate_dps: PyOnceLock<Py<PyArray2<f32>>>,
    temperature_raw: PyOnceLock<Py<PyArray2<i16>>>,
    since_power_on: PyOnceLock<Py<PyArray1<u32>>>,
    since_power_on_ms: PyOnceLock<Py<PyArray1<u32>>>,
}

impl Default for Arrays {
    fn default() -> Self {
        Self {
            rate_dps: PyOnceLock::new(),
            temperature_raw: PyOnceLock::new(),
            since_power_on: PyOnceLock::new(),
            since_power_on_ms: PyOnceLock::new(),
        }
    }
}

/// One activation (switch-on to switch-off) of one unit: what the fitter consumes.
#[pyclass(module = "gyrodrift", name = "Segment", frozen)]
pub struct PySegment {
    pub segment: Arc<Segment>,
    arrays: Arrays,
}

impl PySegment {
    /// Wraps a segment read or built in Rust.
    pub fn wrap(segment: Segment) -> Self {
        Self {
            segment: Arc::new(segment),
            arrays: Arrays::default(),
        }
    }
}

/// One entry of the `aux` argument: an `AuxChannel` or a `(values, unit, sample_rate_hz)` tuple.
fn aux_entry(py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> PyResult<AuxChannel> {
    if let Ok(channel) = value.cast::<PyAuxChannel>() {
        return Ok(channel.get().channel.clone());
    }
    let tuple = value.cast::<PyTuple>().ok().filter(|t| t.len() == 3);
    let Some(tuple) = tuple else {
        return Err(Error::Input(format!(
            "`aux[{name:?}]` must be a gyrodrift.AuxChannel or a (values, unit, sample_rate_hz) tuple, got {}",
            describe(value)
        ))
        .into());
    };
    let channel = PyAuxChannel::new(
        py,
        &tuple.get_item(0)?,
        &tuple.get_item(1)?,
        &tuple.get_item(2)?,
    )
    .map_err(|error| {
        // Name the channel: "`values` must ..." alone would not say which one.
        let message = error.value(py).to_string();
        PyErr::from(Error::Input(format!("aux[{name:?}]: {message}")))
    })?;
    Ok(channel.channel)
}

fn aux_channels(
    py: Python<'_>,
    aux: Option<&Bound<'_, PyAny>>,
) -> PyResult<BTreeMap<String, AuxChannel>> {
    let Some(aux) = aux.filter(|a| !a.is_none()) else {
        return Ok(BTreeMap::new());
    };
    let dict = aux.cast::<PyDict>().map_err(|_| {
        Error::Input(format!(
            "`aux` must be a dict of channel name → AuxChannel or (values, unit, sample_rate_hz), got {}",
            describe(aux)
        ))
    })?;
    let mut channels = BTreeMap::new();
    for (key, value) in dict.iter() {
        let name: String = args::value("aux key", "a str channel name", &key)?;
        let channel = aux_entry(py, &name, &value)?;
        channels.insert(name, channel);
    }
    Ok(channels)
}

#[pymethods]
impl PySegment {
    /// One activation built from arrays: `rate_dps` float32/float64 (n, 3) in °/s and
    /// `temperature_raw` int16 (n, 3), consecutive samples from switch-on at `sample_rate_hz`,
    /// at `temperature_raw_per_celsius` (default 200) with `temperature_raw_at_zero_celsius`
    /// (default 0) read at 0 °C.
    #[new]
    #[pyo3(signature = (labels, rate_dps, temperature_raw, *, sample_rate_hz = None, power_on_ns = None, aux = None, temperature_raw_per_celsius = None, temperature_raw_at_zero_celsius = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        labels: &Bound<'_, PyAny>,
        rate_dps: &Bound<'_, PyAny>,
        temperature_raw: &Bound<'_, PyAny>,
        sample_rate_hz: Option<&Bound<'_, PyAny>>,
        power_on_ns: Option<&Bound<'_, PyAny>>,
        aux: Option<&Bound<'_, PyAny>>,
        temperature_raw_per_celsius: Option<&Bound<'_, PyAny>>,
        temperature_raw_at_zero_celsius: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let mut temperature_scale = drift_recording::TemperatureScale::default();
        if let Some(v) = args::optional::<f64>(
            "temperature_raw_per_celsius",
            "a float > 0 (raw units per °C)",
            temperature_raw_per_celsius,
        )? {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Input(format!(
                    "`temperature_raw_per_celsius` must be a finite number > 0 (raw units per °C), got {v}"
                ))
                .into());
            }
            temperature_scale.raw_per_celsius = v;
        }
        if let Some(v) = args::optional::<f64>(
            "temperature_raw_at_zero_celsius",
            "a float (raw units)",
            temperature_raw_at_zero_celsius,
        )? {
            if !v.is_finite() {
                return Err(Error::Input(format!(
                    "`temperature_raw_at_zero_celsius` must be a finite number (raw units), got {v}"
                ))
                .into());
            }
            temperature_scale.raw_at_zero_celsius = v;
        }
        let labels = labels.cast::<PyLabels>().map_err(|_| {
            Error::Input(format!(
                "`labels` must be a gyrodrift.Labels, got {}",
                describe(labels)
            ))
        })?;
        let rates = Rows::borrow("rate_dps", rate_dps)?;
        let rates = rates.view();
        if let Some((row, axis)) = rates.first_non_finite() {
            return Err(Error::Input(format!(
                "`rate_dps` must be finite (the recording format stores no NaN or inf), got a non-finite value at row {row}, axis {}",
                ["X", "Y", "Z"].get(axis).unwrap_or(&"?")
            ))
            .into());
        }
        let raw = raw_rows("temperature_raw", temperature_raw)?;
        let raw = raw.as_array();
        let n = rates.len();
        if raw.nrows() != n {
            return Err(Error::Input(format!(
                "`temperature_raw` must have one row per row of `rate_dps` ({n}), got {} rows",
                raw.nrows()
            ))
            .into());
        }
        let n_u32 = u32::try_from(n).map_err(|_| {
            Error::Input(format!(
                "a segment holds at most 4294967295 samples, got {n}"
            ))
        })?;
        let sample_rate_hz = match sample_rate_hz {
            Some(v) => check_sample_rate("sample_rate_hz", v)?,
            None => 1000,
        };
        let power_on_ns: u64 =
            args::optional("power_on_ns", "an integer ≥ 0 (ns)", power_on_ns)?.unwrap_or(0);
        let segment = Segment {
            labels: labels.get().0.clone(),
            sample_rate_hz,
            power_on_ns,
            since_power_on: (0..n_u32).collect(),
            rate_dps: [0, 1, 2].map(|axis| rates.column(axis)),
            temperature_raw: [0, 1, 2].map(|axis| raw.column(axis).to_vec()),
            temperature_scale,
            aux: aux_channels(py, aux)?,
        };
        Ok(Self::wrap(segment))
    }

    /// Raw temperature units per °C of `temperature_raw` (the recording's sensor scale).
    #[getter]
    fn temperature_raw_per_celsius(&self) -> f64 {
        self.segment.temperature_scale.raw_per_celsius
    }

    /// The raw temperature reading at 0 °C.
    #[getter]
    fn temperature_raw_at_zero_celsius(&self) -> f64 {
        self.segment.temperature_scale.raw_at_zero_celsius
    }

    /// The activation's labels.
    #[getter]
    fn labels(&self) -> PyLabels {
        PyLabels(self.segment.labels.clone())
    }

    /// Gyro and temperature sample rate, Hz.
    #[getter]
    fn sample_rate_hz(&self) -> u32 {
        self.segment.sample_rate_hz
    }

    /// Switch-on time on the recording clock, ns.
    #[getter]
    fn power_on_ns(&self) -> u64 {
        self.segment.power_on_ns
    }

    fn __len__(&self) -> usize {
        self.segment.len()
    }

    /// Sample index since switch-on (uint32, (n,); 0 = switch-on). Read-only.
    #[getter]
    fn since_power_on(&self, py: Python<'_>) -> PyResult<Py<PyArray1<u32>>> {
        self.arrays
            .since_power_on
            .get_or_try_init(py, || {
                Ok(read_only(vector(py, self.segment.since_power_on.clone()))?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Milliseconds since switch-on (uint32, (n,)): what `Corrector.correct_batch` takes, computed
    /// as the evaluation does (index × 1000 / rate, rounded down). Read-only.
    #[getter]
    fn since_power_on_ms(&self, py: Python<'_>) -> PyResult<Py<PyArray1<u32>>> {
        self.arrays
            .since_power_on_ms
            .get_or_try_init(py, || {
                let rate = u64::from(self.segment.sample_rate_hz.max(1));
                let ms = self
                    .segment
                    .since_power_on
                    .iter()
                    .map(|&i| u32::try_from(u64::from(i) * 1000 / rate).unwrap_or(u32::MAX))
                    .collect();
                Ok(read_only(vector(py, ms))?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Angular rate X, Y, Z per sample, °/s (float32, (n, 3)). Read-only.
    #[getter]
    fn rate_dps(&self, py: Python<'_>) -> PyResult<Py<PyArray2<f32>>> {
        self.arrays
            .rate_dps
            .get_or_try_init(py, || {
                Ok(read_only(columns(py, &self.segment.rate_dps)?)?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Raw temperature X, Y, Z per sample (int16, (n, 3); 200 per °C). Read-only.
    #[getter]
    fn temperature_raw(&self, py: Python<'_>) -> PyResult<Py<PyArray2<i16>>> {
        self.arrays
            .temperature_raw
            .get_or_try_init(py, || {
                Ok(read_only(columns(py, &self.segment.temperature_raw)?)?.unbind())
            })
            .map(|a| a.clone_ref(py))
    }

    /// Auxiliary channels by name (a new dict on each access).
    #[getter]
    fn aux<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (name, channel) in &self.segment.aux {
            dict.set_item(name, PyAuxChannel::wrap(py, channel.clone())?)?;
        }
        Ok(dict)
    }

    /// One auxiliary channel; `InputError` naming the channels there are if `name` is not one.
    fn aux_channel(&self, py: Python<'_>, name: &Bound<'_, PyAny>) -> PyResult<PyAuxChannel> {
        let name = args::text("name", name)?;
        let Some(channel) = self.segment.aux.get(&name) else {
            let known: Vec<&str> = self.segment.aux.keys().map(String::as_str).collect();
            return Err(Error::Input(format!(
                "unknown channel {name:?}: this segment has {}",
                if known.is_empty() {
                    "no auxiliary channels".to_owned()
                } else {
                    known.join(", ")
                }
            ))
            .into());
        };
        PyAuxChannel::wrap(py, channel.clone())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let l = &self.segment.labels;
        format!(
            "<Segment {} {:+} °C {} series {} repeat {} activation {}: {} samples at {} Hz>",
            l.unit_id,
            l.set_point_celsius,
            l.series_kind.as_str(),
            l.series,
            l.repeat,
            l.activation,
            self.segment.len(),
            self.segment.sample_rate_hz
        )
    }
}
