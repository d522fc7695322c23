//! Topics, schemas (ROS 2 `.msg` definitions, MCAP schema encoding `ros2msg`) and the
//! message types carried on them (MCAP message encoding `cdr`).
//!
//! `ros2msg` + `cdr` is a well-known MCAP encoding pair: Foxglove decodes it natively and
//! Python reads it with `mcap` + `mcap-ros2-support` (or a few lines of `struct`). It is a
//! compact binary layout, which JSON is not: see `docs/recording-format.md` for the sizes
//! and throughputs that decided it.

use crate::cdr::{DecodeError, Decoder, Encoder};

/// Gyro angular rates, °/s, per sample (batch of consecutive samples).
pub const TOPIC_RATE: &str = "/gyro/rate";
/// Raw temperature-sensor readings per axis, 200 raw units per °C, per sample.
pub const TOPIC_TEMPERATURE_RAW: &str = "/gyro/temperature_raw";
/// Prefix of every auxiliary topic: the fixed ones below, and `/aux/<name>` for each named
/// channel (a [`ScalarBatch`], unit in the channel metadata `unit`; see [`crate::check_named_aux_channel`]).
pub const AUX_PREFIX: &str = "/aux/";
/// Accelerometer, g, 100 Hz.
pub const TOPIC_ACCEL: &str = "/aux/accel";
/// Supply voltage, V, 100 Hz.
pub const TOPIC_SUPPLY: &str = "/aux/supply_voltage";
/// Chamber set point, °C, 100 Hz (while the unit is powered).
pub const TOPIC_SET_POINT: &str = "/aux/chamber_set_point";
/// Power on/off events with the protocol labels.
pub const TOPIC_POWER: &str = "/power/state";
/// Prefix of every ground-truth topic (only ever in `.truth.mcap` sidecars).
pub const TRUTH_PREFIX: &str = "/truth/";
/// Truth: noise-free systematic bias per sample (°/s), including the turn-on jitter.
pub const TOPIC_TRUTH_BIAS: &str = "/truth/systematic_bias";
/// Truth: element temperatures (°C), 100 Hz.
pub const TOPIC_TRUTH_ELEMENT: &str = "/truth/element_temperature";
/// Truth: ASIC temperatures (°C, without sensor offset/noise), 100 Hz.
pub const TOPIC_TRUTH_ASIC: &str = "/truth/asic_temperature";
/// Truth: Gauss–Markov bias instability (°/s), 100 Hz.
pub const TOPIC_TRUTH_INSTABILITY: &str = "/truth/bias_instability";
/// Truth: a world's undeclared effects alone (°/s), 100 Hz: the part of the systematic bias an
/// oracle regresses on (only in the sidecars of a drawn world).
pub const TOPIC_TRUTH_EFFECT: &str = "/truth/hidden_effect_bias";

/// MCAP profile of recordings.
pub const PROFILE_RECORDING: &str = "gyrodrift";
/// MCAP profile of ground-truth sidecars.
pub const PROFILE_TRUTH: &str = "gyrodrift-truth";
/// MCAP metadata record name of a recording's labels.
pub const METADATA_RECORDING: &str = "gyrodrift.recording";
/// Format version written into the metadata.
pub const FORMAT_VERSION: &str = "1";

/// Schema name and `.msg` text of [`Vector3Batch`].
pub const SCHEMA_VECTOR3: (&str, &str) = (
    "gyrodrift_msgs/msg/Vector3Batch",
    "# Consecutive samples of a 3-axis quantity at a fixed rate. Unit: channel metadata `unit`.\n\
uint32 first_sample   # index of x[0] counted from switch-on at sample_rate_hz (0 = switch-on)\n\
uint32 sample_rate_hz\n\
float32[] x\n\
float32[] y\n\
float32[] z\n",
);
/// Schema name and `.msg` text of [`RawTemperatureBatch`].
pub const SCHEMA_RAW_TEMPERATURE: (&str, &str) = (
    "gyrodrift_msgs/msg/RawTemperatureBatch",
    "# Consecutive raw temperature-sensor readings per axis (200 raw units per degree C).\n\
uint32 first_sample   # index of x[0] counted from switch-on at sample_rate_hz (0 = switch-on)\n\
uint32 sample_rate_hz\n\
int16[] x\n\
int16[] y\n\
int16[] z\n",
);
/// Schema name and `.msg` text of [`ScalarBatch`].
pub const SCHEMA_SCALAR: (&str, &str) = (
    "gyrodrift_msgs/msg/ScalarBatch",
    "# Consecutive samples of a scalar at a fixed rate. Unit: channel metadata `unit`.\n\
uint32 first_sample   # index of values[0] counted from switch-on at sample_rate_hz\n\
uint32 sample_rate_hz\n\
float32[] values\n",
);
/// Schema name and `.msg` text of [`PowerEvent`].
pub const SCHEMA_POWER: (&str, &str) = (
    "gyrodrift_msgs/msg/PowerEvent",
    "# Switch-on (powered = true) or switch-off of the unit, with the protocol labels.\n\
bool powered\n\
string series_kind      # \"protocol\" or \"field\"\n\
uint32 series           # series number within the file, from 1\n\
uint32 repeat           # repeat of this interval, from 1 (field: 1)\n\
uint32 activation       # activation number within the series, from 1\n\
float64 interval_min    # protocol off-time between activations (min); NaN for field series\n\
float64 off_before_s    # time off before this switch-on (s); NaN if unknown\n\
float64 set_point_celsius  # chamber set point at this event (degrees C)\n",
);

/// A batch of 3-axis `f32` samples.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Vector3Batch {
    /// Index of the first sample since switch-on.
    pub first_sample: u32,
    /// Sample rate (Hz).
    pub sample_rate_hz: u32,
    /// X, Y, Z samples (equal lengths).
    pub xyz: [Vec<f32>; 3],
}

/// A batch of raw temperature readings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawTemperatureBatch {
    /// Index of the first sample since switch-on.
    pub first_sample: u32,
    /// Sample rate (Hz).
    pub sample_rate_hz: u32,
    /// X, Y, Z readings (equal lengths), raw units.
    pub xyz: [Vec<i16>; 3],
}

/// A batch of scalar samples.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScalarBatch {
    /// Index of the first sample since switch-on.
    pub first_sample: u32,
    /// Sample rate (Hz).
    pub sample_rate_hz: u32,
    /// Samples.
    pub values: Vec<f32>,
}

/// Power switching with labels.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerEvent {
    /// true = switch-on.
    pub powered: bool,
    /// `"protocol"` or `"field"`.
    pub series_kind: String,
    /// Series number within the file (from 1).
    pub series: u32,
    /// Repeat of the interval (from 1).
    pub repeat: u32,
    /// Activation within the series (from 1).
    pub activation: u32,
    /// Protocol interval (min), NaN for field.
    pub interval_min: f64,
    /// Off-time before the switch-on (s), NaN if unknown.
    pub off_before_s: f64,
    /// Chamber set point (°C).
    pub set_point_celsius: f64,
}

impl Vector3Batch {
    /// Encodes into `enc`.
    pub fn encode<'e>(
        first_sample: u32,
        rate: u32,
        xyz: [&[f32]; 3],
        enc: &'e mut Encoder,
    ) -> &'e [u8] {
        enc.begin()
            .u32(first_sample)
            .u32(rate)
            .f32s(xyz[0])
            .f32s(xyz[1])
            .f32s(xyz[2])
            .bytes()
    }
    /// Decodes, appending samples to `xyz` (so callers can decode straight into a segment).
    pub fn decode_into(
        data: &[u8],
        xyz: &mut [Vec<f32>; 3],
    ) -> Result<(u32, u32, usize), DecodeError> {
        let mut d = Decoder::new(data)?;
        let first = d.u32()?;
        let rate = d.u32()?;
        let n = d.f32s_into(&mut xyz[0])?;
        let ny = d.f32s_into(&mut xyz[1])?;
        let nz = d.f32s_into(&mut xyz[2])?;
        if ny != n || nz != n {
            return Err(format!("axis lengths differ: x {n}, y {ny}, z {nz}"));
        }
        Ok((first, rate, n))
    }
}

impl RawTemperatureBatch {
    /// Encodes into `enc`.
    pub fn encode<'e>(
        first_sample: u32,
        rate: u32,
        xyz: [&[i16]; 3],
        enc: &'e mut Encoder,
    ) -> &'e [u8] {
        enc.begin()
            .u32(first_sample)
            .u32(rate)
            .i16s(xyz[0])
            .i16s(xyz[1])
            .i16s(xyz[2])
            .bytes()
    }
    /// Decodes, appending readings to `xyz`.
    pub fn decode_into(
        data: &[u8],
        xyz: &mut [Vec<i16>; 3],
    ) -> Result<(u32, u32, usize), DecodeError> {
        let mut d = Decoder::new(data)?;
        let first = d.u32()?;
        let rate = d.u32()?;
        let n = d.i16s_into(&mut xyz[0])?;
        let ny = d.i16s_into(&mut xyz[1])?;
        let nz = d.i16s_into(&mut xyz[2])?;
        if ny != n || nz != n {
            return Err(format!("axis lengths differ: x {n}, y {ny}, z {nz}"));
        }
        Ok((first, rate, n))
    }
}

impl ScalarBatch {
    /// Encodes into `enc`.
    pub fn encode<'e>(
        first_sample: u32,
        rate: u32,
        values: &[f32],
        enc: &'e mut Encoder,
    ) -> &'e [u8] {
        enc.begin().u32(first_sample).u32(rate).f32s(values).bytes()
    }
    /// Decodes, appending samples to `values`.
    pub fn decode_into(
        data: &[u8],
        values: &mut Vec<f32>,
    ) -> Result<(u32, u32, usize), DecodeError> {
        let mut d = Decoder::new(data)?;
        let first = d.u32()?;
        let rate = d.u32()?;
        let n = d.f32s_into(values)?;
        Ok((first, rate, n))
    }
}

impl PowerEvent {
    /// Encodes into `enc`.
    pub fn encode<'e>(&self, enc: &'e mut Encoder) -> &'e [u8] {
        enc.begin()
            .bool(self.powered)
            .string(&self.series_kind)
            .u32(self.series)
            .u32(self.repeat)
            .u32(self.activation)
            .f64(self.interval_min)
            .f64(self.off_before_s)
            .f64(self.set_point_celsius)
            .bytes()
    }
    /// Decodes one event.
    pub fn decode(data: &[u8]) -> Result<Self, DecodeError> {
        let mut d = Decoder::new(data)?;
        Ok(Self {
            powered: d.bool()?,
            series_kind: d.string()?,
            series: d.u32()?,
            repeat: d.u32()?,
            activation: d.u32()?,
            interval_min: d.f64()?,
            off_before_s: d.f64()?,
            set_point_celsius: d.f64()?,
        })
    }
}
