//! `gyrodrift.Recording.from_dataframe` / `read_csv`, Rust side: CSV text (what `gyrodrift.frames`
//! makes of a DataFrame) through drift-recording's validating CSV reader, the one `gyrodrift
//! import` uses, so a frame and a file are checked alike (errors name the row and the column).

use std::path::Path;

use drift_recording::{
    read_csv_bytes, CsvColumns, CsvOptions, CsvTiming, RateUnit, SeriesKind, TimeUnit,
};
use pyo3::prelude::*;

use crate::errors::Error;
use crate::recording::PyRecording;

/// Reads CSV text whose header names the columns given; `name` stands for the source in errors.
#[pyfunction]
#[pyo3(name = "_read_csv_text", signature = (
    data, name, *, time, rate, temperature, activation, rate_unit, unit_id, sample_rate_hz,
    max_gap_s, set_point_celsius, series_kind, temperature_dropouts,
))]
#[allow(clippy::too_many_arguments)]
pub fn read_csv_text(
    py: Python<'_>,
    data: &[u8],
    name: &str,
    time: String,
    rate: [String; 3],
    temperature: [String; 3],
    activation: Option<String>,
    rate_unit: &str,
    unit_id: String,
    sample_rate_hz: u32,
    max_gap_s: Option<f64>,
    set_point_celsius: Option<f64>,
    series_kind: &str,
    temperature_dropouts: bool,
) -> PyResult<PyRecording> {
    let rate_unit = RateUnit::parse(rate_unit).ok_or_else(|| {
        Error::Input(format!(
            "`rate_unit` must be 'deg/s' or 'rad/s', got {rate_unit:?}"
        ))
    })?;
    let series_kind = SeriesKind::parse(series_kind).ok_or_else(|| {
        Error::Input(format!(
            "`series_kind` must be 'protocol' or 'field', got {series_kind:?}"
        ))
    })?;
    let options = CsvOptions {
        columns: CsvColumns {
            time_s: time,
            rate_dps: rate,
            temperature_celsius: temperature,
            segment: activation,
            accel_g: None,
            supply_voltage: None,
            aux: Vec::new(),
        },
        sample_rate_hz,
        timing: max_gap_s.map_or(CsvTiming::Strict, |max_gap_s| CsvTiming::Resample {
            max_gap_s,
        }),
        unit_id,
        set_point_celsius,
        series_kind,
        temperature_dropouts,
        rate_unit,
        time_unit: TimeUnit::Seconds,
        ..CsvOptions::default()
    };
    let recording = py
        .detach(|| read_csv_bytes(Path::new(name), data, &options))
        .map_err(|e| Error::Input(e.to_string()))?;
    PyRecording::wrap(py, recording)
}
