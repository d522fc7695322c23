//! One activation and its labels.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The scale every writer of this crate (and the simulator) stores raw temperatures at: raw units
/// per °C (the paper's sensor: 1 °C = 200 units). Readers do not assume it: a recording says its
/// own scale ([`TemperatureScale`]), which travels with each [`Segment`].
pub const RAW_PER_CELSIUS: f64 = 200.0;

/// The recording metadata key of the temperature scale (raw units per °C).
pub const SCALE_KEY: &str = "temperature_raw_per_celsius";

/// The recording metadata key of the raw reading at 0 °C (optional: 0 when absent).
pub const ZERO_KEY: &str = "temperature_raw_at_zero_celsius";

/// How a sensor's raw temperature reading maps to °C: `°C = (raw − raw_at_zero_celsius) /
/// raw_per_celsius`. Read from the recording (`temperature_raw_per_celsius`,
/// `temperature_raw_at_zero_celsius`), carried by each activation, stamped into fitted tables.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TemperatureScale {
    /// Raw units per °C (positive, finite).
    pub raw_per_celsius: f64,
    /// Raw reading at 0 °C (finite).
    pub raw_at_zero_celsius: f64,
}

impl Default for TemperatureScale {
    fn default() -> Self {
        Self {
            raw_per_celsius: RAW_PER_CELSIUS,
            raw_at_zero_celsius: 0.0,
        }
    }
}

impl TemperatureScale {
    /// A raw reading in °C.
    pub fn celsius(&self, raw: f64) -> f64 {
        (raw - self.raw_at_zero_celsius) / self.raw_per_celsius
    }

    /// A temperature difference of `raw` units in °C (the offset cancels).
    pub fn celsius_difference(&self, raw: f64) -> f64 {
        raw / self.raw_per_celsius
    }

    /// °C as a raw reading (not rounded).
    pub fn raw(&self, celsius: f64) -> f64 {
        celsius * self.raw_per_celsius + self.raw_at_zero_celsius
    }

    /// The scale a recording's metadata gives: [`SCALE_KEY`] (the default scale when absent, as
    /// in recordings written before the key existed) and [`ZERO_KEY`] (0 when absent). A value
    /// that is there must be a finite number (a positive one for the scale): the message names
    /// the key and the value.
    pub fn from_metadata(metadata: &BTreeMap<String, String>) -> Result<Self, String> {
        let number = |key: &str, default: f64| match metadata.get(key) {
            None => Ok(default),
            Some(text) => match text.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!("{key} must be a finite number, got `{text}`")),
            },
        };
        let scale = Self {
            raw_per_celsius: number(SCALE_KEY, RAW_PER_CELSIUS)?,
            raw_at_zero_celsius: number(ZERO_KEY, 0.0)?,
        };
        if scale.raw_per_celsius <= 0.0 {
            return Err(format!(
                "{SCALE_KEY} must be greater than zero (raw units per °C), got {}",
                scale.raw_per_celsius
            ));
        }
        Ok(scale)
    }

    /// The metadata entries that give this scale back through [`Self::from_metadata`].
    pub fn metadata(&self) -> [(&'static str, String); 2] {
        [
            (SCALE_KEY, format!("{}", self.raw_per_celsius)),
            (ZERO_KEY, format!("{}", self.raw_at_zero_celsius)),
        ]
    }
}

/// The raw temperature value that marks a missing reading (a temperature-sensor dropout) in
/// `/gyro/temperature_raw` and in [`Segment::temperature_raw`]. A raw temperature is an `int16`,
/// which has no NaN; −32768 (−163.84 °C at 200 raw/°C) is outside any sensor's range, so it cannot
/// be mistaken for a reading. Rates have no such marker: a NaN rate is refused by the reader.
pub const TEMPERATURE_MISSING_RAW: i16 = i16::MIN;

/// A raw temperature as the corrector takes it: the reading as `f32`, or NaN for
/// [`TEMPERATURE_MISSING_RAW`] (the corrector then holds its last good drift and flags
/// `TEMPERATURE_INVALID`).
pub fn temperature_reading(raw: i16) -> f32 {
    if raw == TEMPERATURE_MISSING_RAW {
        f32::NAN
    } else {
        f32::from(raw)
    }
}

/// Which kind of series an activation belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SeriesKind {
    /// The paper's calibration protocol.
    Protocol,
    /// A field-like session.
    Field,
}

impl SeriesKind {
    /// The label written into recordings.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Protocol => "protocol",
            Self::Field => "field",
        }
    }

    /// Parses a label.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "protocol" => Some(Self::Protocol),
            "field" => Some(Self::Field),
            _ => None,
        }
    }
}

/// The labels of one activation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentLabels {
    /// Unit id (from the recording metadata).
    pub unit_id: String,
    /// Chamber set point at switch-on (°C): the power event's. In a field session whose chamber
    /// ramps, this is the ambient of the moment, not the session's set point.
    pub set_point_celsius: f64,
    /// The chamber set point the whole recording was made at (°C; the recording metadata's
    /// `set_point_celsius`, nominal for field files); `None` when the metadata does not say, or
    /// says the same as `set_point_celsius` (one form per meaning: labels round-trip).
    /// Which set point an activation *belongs to* (calibration, validation) is this one: with
    /// ambient ramps almost no activation switches on exactly at the nominal set point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub session_set_point_celsius: Option<f64>,
    /// Protocol or field.
    pub series_kind: SeriesKind,
    /// Series number within the file (from 1).
    pub series: u32,
    /// Repeat of the interval (from 1).
    pub repeat: u32,
    /// Activation number within the series (from 1; 1..5 in the paper's protocol).
    pub activation: u32,
    /// Protocol off-time between activations (min); `None` for field sessions.
    pub interval_min: Option<f64>,
    /// Off-time before this switch-on as logged by the bench (s); `None` if unknown.
    pub off_before_s: Option<f64>,
}

impl SegmentLabels {
    /// The set point the activation belongs to: the recording's nominal set point when it gives
    /// one, else the chamber set point at switch-on (a recording without the metadata key, or a
    /// segment made in memory).
    pub fn nominal_set_point_celsius(&self) -> f64 {
        self.session_set_point_celsius
            .unwrap_or(self.set_point_celsius)
    }
}

/// An auxiliary channel of one activation, at its own rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuxChannel {
    /// Physical unit (`g`, `V`, `degC`).
    pub unit: String,
    /// Sample rate (Hz).
    pub sample_rate_hz: u32,
    /// Samples; sample `k` is at `k / sample_rate_hz` seconds after switch-on.
    pub values: Vec<f32>,
}

/// One activation (switch-on to switch-off): what the fitter consumes.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Labels.
    pub labels: SegmentLabels,
    /// Gyro/temperature sample rate (Hz).
    pub sample_rate_hz: u32,
    /// Switch-on time on the recording clock (ns).
    pub power_on_ns: u64,
    /// Per sample: index since switch-on (0 = switch-on); time = index / `sample_rate_hz`.
    pub since_power_on: Vec<u32>,
    /// Per sample: angular rate X, Y, Z (°/s).
    pub rate_dps: [Vec<f32>; 3],
    /// Per sample: raw temperature X, Y, Z, at [`Self::temperature_scale`].
    pub temperature_raw: [Vec<i16>; 3],
    /// How `temperature_raw` maps to °C (the recording's own sensor scale).
    pub temperature_scale: TemperatureScale,
    /// Auxiliary channels by name: the format's own `accel_x`, `accel_y`, `accel_z` (g),
    /// `supply_voltage` (V), `chamber_set_point` (°C), and any named ones (`/aux/<name>` in a
    /// recording; [`crate::check_named_aux_channel`]).
    pub aux: BTreeMap<String, AuxChannel>,
}

impl Segment {
    /// The auxiliary channel `name`'s value at switch-on (its first), when it is logged and
    /// finite: what a bench or an instrument read as the activation began.
    pub fn aux_at_switch_on(&self, name: &str) -> Option<f32> {
        self.aux
            .get(name)?
            .values
            .first()
            .copied()
            .filter(|v| v.is_finite())
    }

    /// Number of gyro samples.
    pub fn len(&self) -> usize {
        self.since_power_on.len()
    }

    /// True if the segment has no samples.
    pub fn is_empty(&self) -> bool {
        self.since_power_on.is_empty()
    }

    /// Time since switch-on of sample `i` in integer milliseconds (`None` past the end).
    pub fn since_power_on_ms(&self, i: usize) -> Option<u64> {
        let index = *self.since_power_on.get(i)?;
        Some(u64::from(index) * 1000 / u64::from(self.sample_rate_hz.max(1)))
    }

    /// Raw temperature of `axis` at sample `i` in °C (`None` past the end; NaN for a missing
    /// reading, [`TEMPERATURE_MISSING_RAW`]).
    pub fn temperature_celsius(&self, axis: usize, i: usize) -> Option<f64> {
        let raw = *self.temperature_raw.get(axis)?.get(i)?;
        Some(
            self.temperature_scale
                .celsius(f64::from(temperature_reading(raw))),
        )
    }

    /// The first missing temperature reading ([`TEMPERATURE_MISSING_RAW`]) as `(axis, sample)`.
    pub fn first_missing_temperature(&self) -> Option<(usize, usize)> {
        // Block by block: a test without an early exit vectorises (every calibration activation is
        // scanned whole before it is analysed); the sample is looked for only in a block that has
        // one.
        const BLOCK: usize = 256;
        self.temperature_raw
            .iter()
            .enumerate()
            .find_map(|(axis, raw)| {
                raw.chunks(BLOCK).enumerate().find_map(|(block, readings)| {
                    let missing = |&r: &i16| r == TEMPERATURE_MISSING_RAW;
                    if !readings.iter().fold(false, |any, r| any | missing(r)) {
                        return None;
                    }
                    let i = readings.iter().position(missing)?;
                    Some((axis, block * BLOCK + i))
                })
            })
    }
}
