//! Writing recordings in the bench format: used by the simulator, and by anything that
//! converts real test-bench logs (give it [`Recording`] segments, get the same MCAP).

use crate::error::WriteError;
use crate::layout::{aux_every, AUX_RATE_HZ};
use crate::read::Recording;
use crate::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use crate::segment::{Segment, TemperatureScale};
use crate::writable::check_writable;
use crate::writer::McapFile;
use std::collections::BTreeMap;
use std::path::Path;

/// Creates a recording file with every topic registered and the metadata record written.
///
/// `metadata` must carry at least `unit_id` and `sample_rate_hz` (see
/// `docs/recording-format.md` for every key).
pub fn create_recording(
    path: &Path,
    metadata: BTreeMap<String, String>,
) -> Result<McapFile, WriteError> {
    let scale =
        TemperatureScale::from_metadata(&metadata).map_err(|reason| WriteError::Invalid {
            path: path.to_path_buf(),
            reason,
        })?;
    let raw_per_celsius = format!("{}", scale.raw_per_celsius);
    let mut f = McapFile::create(path, schema::PROFILE_RECORDING, mcap::Compression::Zstd)?;
    f.add_topic(
        schema::TOPIC_RATE,
        schema::SCHEMA_VECTOR3,
        &[("unit", "deg/s"), ("frame", "unit body X, Y, Z")],
    )?;
    f.add_topic(
        schema::TOPIC_TEMPERATURE_RAW,
        schema::SCHEMA_RAW_TEMPERATURE,
        &[
            ("unit", "raw"),
            ("raw_per_celsius", raw_per_celsius.as_str()),
        ],
    )?;
    f.add_topic(
        schema::TOPIC_ACCEL,
        schema::SCHEMA_VECTOR3,
        &[("unit", "g"), ("frame", "unit body X, Y, Z")],
    )?;
    f.add_topic(
        schema::TOPIC_SUPPLY,
        schema::SCHEMA_SCALAR,
        &[("unit", "V")],
    )?;
    f.add_topic(
        schema::TOPIC_SET_POINT,
        schema::SCHEMA_SCALAR,
        &[("unit", "degC")],
    )?;
    f.add_topic(schema::TOPIC_POWER, schema::SCHEMA_POWER, &[])?;
    f.metadata(schema::METADATA_RECORDING, metadata)?;
    Ok(f)
}

fn aux<'a>(segment: &'a Segment, name: &str) -> &'a [f32] {
    segment.aux.get(name).map_or(&[], |c| c.values.as_slice())
}

fn event(segment: &Segment, powered: bool) -> PowerEvent {
    let l = &segment.labels;
    PowerEvent {
        powered,
        series_kind: l.series_kind.as_str().to_owned(),
        series: l.series,
        repeat: l.repeat,
        activation: l.activation,
        interval_min: l.interval_min.unwrap_or(f64::NAN),
        off_before_s: l.off_before_s.unwrap_or(f64::NAN),
        set_point_celsius: l.set_point_celsius,
    }
}

/// Writes a whole recording (metadata and segments) to `path` in batches of 100 ms.
/// Reading the result with [`crate::read_recording`] gives back an identical [`Recording`]
/// (apart from `path`, and the format's own auxiliary channels, which every segment read back
/// has, empty if it had none).
///
/// Auxiliary channels other than the format's own are written as named channels, each a
/// `ScalarBatch` on its own topic `/aux/<name>` with its unit in the channel metadata, in the
/// activations that have them. Every channel must be at 100 Hz ([`AUX_RATE_HZ`]), finite, no
/// longer than its activation, in the format's unit for its own channels and in one unit per
/// named channel, with a name [`crate::check_named_aux_channel`] accepts; otherwise
/// [`WriteError::Invalid`] names the segment and the channel, and nothing is written.
pub fn write_recording(recording: &Recording, path: &Path) -> Result<u64, WriteError> {
    let named = check_writable(recording).map_err(|reason| WriteError::Invalid {
        path: path.to_path_buf(),
        reason,
    })?;
    // The activations' own scale is what their raw temperatures are at: the file says it.
    let mut metadata = recording.metadata.clone();
    if let Some(first) = recording.segments.first() {
        if TemperatureScale::from_metadata(&metadata) != Ok(first.temperature_scale) {
            for (key, value) in first.temperature_scale.metadata() {
                metadata.insert(key.to_owned(), value);
            }
        }
    }
    let mut f = create_recording(path, metadata)?;
    for channel in &named {
        f.add_topic(
            &channel.topic,
            schema::SCHEMA_SCALAR,
            &[("unit", channel.unit.as_str())],
        )?;
    }
    for segment in &recording.segments {
        let fs = segment.sample_rate_hz;
        let period_ns = 1_000_000_000 / u64::from(fs.max(1));
        // Every log time below is at most the switch-off time: check it once.
        let off_ns = (segment.len() as u64)
            .checked_mul(period_ns)
            .and_then(|d| segment.power_on_ns.checked_add(d))
            .ok_or_else(|| WriteError::Invalid {
                path: path.to_path_buf(),
                reason: format!(
                    "activation at {} ns with {} samples ends beyond the u64 ns clock",
                    segment.power_on_ns,
                    segment.len()
                ),
            })?;
        let batch = (fs / 10).max(1) as usize;
        let aux_every = aux_every(fs);
        f.power(&event(segment, true), segment.power_on_ns)?;
        let n = segment.len();
        let mut first = 0usize;
        while first < n {
            let end = (first + batch).min(n);
            let log_ns = segment.power_on_ns + first as u64 * period_ns;
            let r = &segment.rate_dps;
            Vector3Batch::encode(
                first as u32,
                fs,
                [&r[0][first..end], &r[1][first..end], &r[2][first..end]],
                &mut f.enc,
            );
            f.write_encoded(schema::TOPIC_RATE, log_ns)?;
            let t = &segment.temperature_raw;
            RawTemperatureBatch::encode(
                first as u32,
                fs,
                [&t[0][first..end], &t[1][first..end], &t[2][first..end]],
                &mut f.enc,
            );
            f.write_encoded(schema::TOPIC_TEMPERATURE_RAW, log_ns)?;
            let (a0, a1) = (first.div_ceil(aux_every), end.div_ceil(aux_every));
            // A channel shorter than the activation (or absent, as from a CSV file) continues
            // where it ended, with empty batches: its `first_sample` never jumps ahead of what
            // was written, which the reader would refuse as a gap.
            let start = |name: &str| a0.min(aux(segment, name).len());
            let slice = |name: &str| {
                let v = aux(segment, name);
                &v[a0.min(v.len())..a1.min(v.len())]
            };
            Vector3Batch::encode(
                start("accel_x") as u32,
                AUX_RATE_HZ,
                [slice("accel_x"), slice("accel_y"), slice("accel_z")],
                &mut f.enc,
            );
            f.write_encoded(schema::TOPIC_ACCEL, log_ns)?;
            ScalarBatch::encode(
                start("supply_voltage") as u32,
                AUX_RATE_HZ,
                slice("supply_voltage"),
                &mut f.enc,
            );
            f.write_encoded(schema::TOPIC_SUPPLY, log_ns)?;
            ScalarBatch::encode(
                start("chamber_set_point") as u32,
                AUX_RATE_HZ,
                slice("chamber_set_point"),
                &mut f.enc,
            );
            f.write_encoded(schema::TOPIC_SET_POINT, log_ns)?;
            // Only in the activations that have the channel: the reader then gives it back to
            // exactly those (an empty channel still gets its empty batches).
            for channel in named.iter().filter(|c| segment.aux.contains_key(&c.name)) {
                ScalarBatch::encode(
                    start(&channel.name) as u32,
                    AUX_RATE_HZ,
                    slice(&channel.name),
                    &mut f.enc,
                );
                f.write_encoded(&channel.topic, log_ns)?;
            }
            first = end;
        }
        f.power(&event(segment, false), off_ns)?;
    }
    f.finish()
}
