//! `gyrodrift.Labels`: what an activation is (unit, set point, series kind, series, repeat,
//! activation number, interval), as `drift_recording::SegmentLabels`.

use drift_recording::{SegmentLabels, SeriesKind};
use pyo3::prelude::*;

use crate::args;
use crate::arrays::describe;
use crate::errors::Error;

/// The labels of one activation (`drift_recording::SegmentLabels`).
#[pyclass(module = "gyrodrift", name = "Labels", frozen, eq)]
#[derive(Clone, Debug, PartialEq)]
pub struct PyLabels(pub SegmentLabels);

const COUNT: &str = "an integer in 1..=4294967295";

/// A count label (series, repeat, activation: from 1); 1 when left out.
fn count(name: &str, value: Option<&Bound<'_, PyAny>>) -> Result<u32, Error> {
    match args::optional::<u32>(name, COUNT, value)? {
        None => Ok(1),
        Some(0) => Err(Error::Input(format!("`{name}` must be {COUNT}, got 0"))),
        Some(n) => Ok(n),
    }
}

/// An optional finite, non-negative duration.
fn duration(name: &str, value: Option<&Bound<'_, PyAny>>) -> Result<Option<f64>, Error> {
    match args::optional::<f64>(name, "a finite float ≥ 0 or None", value)? {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(Error::Input(format!(
            "`{name}` must be a finite float ≥ 0 or None, got {v}"
        ))),
        other => Ok(other),
    }
}

/// `series_kind` from its label.
pub fn series_kind(value: &Bound<'_, PyAny>) -> Result<SeriesKind, Error> {
    value
        .extract::<String>()
        .ok()
        .and_then(|text| SeriesKind::parse(&text))
        .ok_or_else(|| {
            let got = value
                .repr()
                .map_or_else(|_| describe(value), |r| r.to_string());
            Error::Input(format!(
                "`series_kind` must be \"protocol\" or \"field\", got {got}"
            ))
        })
}

#[pymethods]
impl PyLabels {
    /// Labels of one activation; validated (counts from 1, finite set point, durations ≥ 0).
    #[new]
    #[pyo3(signature = (
        *,
        unit_id,
        set_point_celsius,
        series_kind = None,
        series = None,
        repeat = None,
        activation = None,
        interval_min = None,
        off_before_s = None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        unit_id: &Bound<'_, PyAny>,
        set_point_celsius: &Bound<'_, PyAny>,
        series_kind: Option<&Bound<'_, PyAny>>,
        series: Option<&Bound<'_, PyAny>>,
        repeat: Option<&Bound<'_, PyAny>>,
        activation: Option<&Bound<'_, PyAny>>,
        interval_min: Option<&Bound<'_, PyAny>>,
        off_before_s: Option<&Bound<'_, PyAny>>,
    ) -> Result<Self, Error> {
        let unit_id: String = args::value("unit_id", "a non-empty str", unit_id)?;
        if unit_id.is_empty() {
            return Err(Error::Input(
                "`unit_id` must be a non-empty str, got ''".into(),
            ));
        }
        let set_point: f64 = args::value("set_point_celsius", "a finite float", set_point_celsius)?;
        if !set_point.is_finite() {
            return Err(Error::Input(format!(
                "`set_point_celsius` must be a finite float, got {set_point}"
            )));
        }
        Ok(Self(SegmentLabels {
            unit_id,
            set_point_celsius: set_point,
            session_set_point_celsius: None,
            series_kind: series_kind.map_or(Ok(SeriesKind::Protocol), self::series_kind)?,
            series: count("series", series)?,
            repeat: count("repeat", repeat)?,
            activation: count("activation", activation)?,
            interval_min: duration("interval_min", interval_min)?,
            off_before_s: duration("off_before_s", off_before_s)?,
        }))
    }

    /// Unit id.
    #[getter]
    fn unit_id(&self) -> &str {
        &self.0.unit_id
    }

    /// Chamber set point at switch-on, °C.
    #[getter]
    fn set_point_celsius(&self) -> f64 {
        self.0.set_point_celsius
    }

    /// The set point the activation belongs to, °C: the recording's nominal one (in a field
    /// session whose ambient ramps, not the ambient at switch-on); the switch-on set point when the
    /// recording does not say, or for labels made in Python.
    #[getter]
    fn nominal_set_point_celsius(&self) -> f64 {
        self.0.nominal_set_point_celsius()
    }

    /// "protocol" or "field".
    #[getter]
    fn series_kind(&self) -> &'static str {
        self.0.series_kind.as_str()
    }

    /// Series number within the recording, from 1.
    #[getter]
    fn series(&self) -> u32 {
        self.0.series
    }

    /// Repeat of the interval, from 1.
    #[getter]
    fn repeat(&self) -> u32 {
        self.0.repeat
    }

    /// Activation number within the series, from 1.
    #[getter]
    fn activation(&self) -> u32 {
        self.0.activation
    }

    /// Protocol off-time between activations, min (None for field sessions).
    #[getter]
    fn interval_min(&self) -> Option<f64> {
        self.0.interval_min
    }

    /// Off-time before this switch-on, s (None if unknown).
    #[getter]
    fn off_before_s(&self) -> Option<f64> {
        self.0.off_before_s
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let l = &self.0;
        format!(
            "Labels(unit_id={:?}, set_point_celsius={:?}, series_kind={:?}, series={}, repeat={}, \
             activation={}, interval_min={}, off_before_s={})",
            l.unit_id,
            l.set_point_celsius,
            l.series_kind.as_str(),
            l.series,
            l.repeat,
            l.activation,
            optional(l.interval_min),
            optional(l.off_before_s)
        )
    }
}

/// `None` or the number, as Python prints it.
fn optional(value: Option<f64>) -> String {
    value.map_or_else(|| "None".to_owned(), |v| format!("{v:?}"))
}
