//! Writing a recording's activations as a ROS 2 bag: one standard message per sample.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::definitions::{
    IMU_DEFINITION, IMU_SCHEMA, IMU_TYPE_HASH, PROFILE_ROS2, TEMPERATURE_DEFINITION,
    TEMPERATURE_SCHEMA, TEMPERATURE_TYPE_HASH,
};
use super::labels::{labels_entries, LABELS_RECORD};
use crate::error::WriteError;
use crate::segment::{temperature_reading, Segment};
use crate::writer::McapFile;

/// Topics of an exported bag.
#[derive(Debug, Clone)]
pub struct ExportTopics {
    /// `sensor_msgs/msg/Imu`, one message per sample.
    pub imu: String,
    /// `sensor_msgs/msg/Temperature` of the X axis's sensor; the Y and Z axes' go to `<this>/y`
    /// and `<this>/z`.
    pub temperature: String,
}

impl ExportTopics {
    /// The temperature topic of each axis.
    pub fn temperature_axes(&self) -> [String; 3] {
        [
            self.temperature.clone(),
            format!("{}/y", self.temperature),
            format!("{}/z", self.temperature),
        ]
    }
}

/// The recording a bag is exported from: what its labels record says of it.
#[derive(Debug, Clone, Copy)]
pub struct ExportSource<'a> {
    /// Unit id (also the messages' `header.frame_id`).
    pub unit_id: &'a str,
    /// The recording's sample rate, Hz.
    pub sample_rate_hz: u32,
    /// The recording's metadata (its set point and series kind are kept).
    pub metadata: &'a BTreeMap<String, String>,
}

/// What [`write_ros2_bag`] wrote, for a bag folder's `metadata.yaml`.
#[derive(Debug, Clone, Copy)]
pub struct WrittenBag {
    /// Bytes of the file.
    pub bytes: u64,
    /// Messages per topic (every topic has one per sample).
    pub messages_per_topic: u64,
    /// First and last message time, ns.
    pub span_ns: (u64, u64),
}

/// Writes `segments` (one unit's activations) as a ROS 2 bag file (rosbag2's MCAP storage,
/// profile `ros2`): per sample one `sensor_msgs/msg/Imu` on `topics.imu` (`angular_velocity` in
/// rad/s; no orientation or acceleration estimate: element 0 of their covariances is −1) and one
/// `sensor_msgs/msg/Temperature` per axis (°C, NaN for a missing reading), with `header.stamp` =
/// log time = the sample's time on the recording clock and `header.frame_id` = the unit id; and
/// the labels record ([`super::LABELS_RECORD`]) that `import rosbag` reads back. Written through a
/// temporary file renamed at the end.
pub fn write_ros2_bag(
    path: &Path,
    segments: &[&Segment],
    source: ExportSource<'_>,
    topics: &ExportTopics,
) -> Result<WrittenBag, WriteError> {
    let invalid = |reason: String| WriteError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let frame_id = source.unit_id;
    let mut f = McapFile::create(path, PROFILE_ROS2, mcap::Compression::Zstd)?;
    // rosbag2's MCAP storage keeps the QoS and (from Jazzy) the type hash in channel metadata.
    f.add_topic(
        &topics.imu,
        (IMU_SCHEMA, IMU_DEFINITION),
        &[
            ("offered_qos_profiles", ""),
            ("topic_type_hash", IMU_TYPE_HASH),
        ],
    )?;
    let temperature_topics = topics.temperature_axes();
    for topic in &temperature_topics {
        f.add_topic(
            topic,
            (TEMPERATURE_SCHEMA, TEMPERATURE_DEFINITION),
            &[
                ("offered_qos_profiles", ""),
                ("topic_type_hash", TEMPERATURE_TYPE_HASH),
            ],
        )?;
    }
    f.metadata(
        LABELS_RECORD,
        labels_entries(
            source.unit_id,
            source.sample_rate_hz,
            source.metadata,
            segments,
        ),
    )?;
    let mut messages = 0u64;
    let mut span: Option<(u64, u64)> = None;
    for (k, segment) in segments.iter().enumerate() {
        let fs = u64::from(segment.sample_rate_hz.max(1));
        let period_ns = 1_000_000_000 / fs;
        let fits = (segment.len() as u64)
            .checked_mul(period_ns)
            .and_then(|d| segment.power_on_ns.checked_add(d))
            .is_some_and(|end| end / 1_000_000_000 <= i32::MAX as u64);
        if !fits {
            return Err(invalid(format!(
                "activation {k} ends beyond a ROS time stamp's range (int32 seconds)"
            )));
        }
        for i in 0..segment.len() {
            let t = segment.power_on_ns + i as u64 * period_ns;
            messages += 1;
            span = Some(span.map_or((t, t), |(a, _)| (a, t)));
            let (sec, nanosec) = ((t / 1_000_000_000) as i32, (t % 1_000_000_000) as u32);
            let w = |axis: usize| f64::from(segment.rate_dps[axis][i]).to_radians();
            let e = f.enc.begin();
            e.i32(sec).u32(nanosec).string(frame_id);
            e.f64(0.0).f64(0.0).f64(0.0).f64(1.0);
            e.f64(-1.0);
            for _ in 1..9 {
                e.f64(0.0);
            }
            e.f64(w(0)).f64(w(1)).f64(w(2));
            for _ in 0..9 {
                e.f64(0.0);
            }
            e.f64(0.0).f64(0.0).f64(0.0);
            e.f64(-1.0);
            for _ in 1..9 {
                e.f64(0.0);
            }
            f.write_encoded(&topics.imu, t)?;
            for (axis, topic) in temperature_topics.iter().enumerate() {
                let celsius = segment
                    .temperature_scale
                    .celsius(f64::from(temperature_reading(
                        segment.temperature_raw[axis][i],
                    )));
                f.enc
                    .begin()
                    .i32(sec)
                    .u32(nanosec)
                    .string(frame_id)
                    .f64(celsius)
                    .f64(0.0);
                f.write_encoded(topic, t)?;
            }
        }
    }
    let bytes = f.finish()?;
    Ok(WrittenBag {
        bytes,
        messages_per_topic: messages,
        span_ns: span.unwrap_or((0, 0)),
    })
}

/// Writes a bag folder as rosbag2 makes one: `<folder>/<name>_0.mcap` ([`write_ros2_bag`]) and
/// `metadata.yaml` (version 8: topics with their type hashes, counts, times), which ROS 2 tools
/// and `rosbags` need to open it. Returns the bytes written.
pub fn write_ros2_bag_folder(
    folder: &Path,
    segments: &[&Segment],
    source: ExportSource<'_>,
    topics: &ExportTopics,
) -> Result<u64, WriteError> {
    let name = folder
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bag".into());
    let file = format!("{name}_0.mcap");
    let written = write_ros2_bag(&folder.join(&file), segments, source, topics)?;
    let (start, end) = written.span_ns;
    let duration = end - start;
    let n = written.messages_per_topic;
    let axes = topics.temperature_axes();
    let all: Vec<(&str, &str, &str)> =
        std::iter::once((topics.imu.as_str(), IMU_SCHEMA, IMU_TYPE_HASH))
            .chain(
                axes.iter()
                    .map(|t| (t.as_str(), TEMPERATURE_SCHEMA, TEMPERATURE_TYPE_HASH)),
            )
            .collect();
    let mut y = String::new();
    let _ = writeln!(y, "rosbag2_bagfile_information:");
    let _ = writeln!(y, "  version: 8");
    let _ = writeln!(y, "  storage_identifier: mcap");
    let _ = writeln!(y, "  duration:\n    nanoseconds: {duration}");
    let _ = writeln!(y, "  starting_time:\n    nanoseconds_since_epoch: {start}");
    let _ = writeln!(y, "  message_count: {}", n * all.len() as u64);
    let _ = writeln!(y, "  topics_with_message_count:");
    for (topic, ty, hash) in &all {
        let _ = writeln!(y, "    - topic_metadata:");
        let _ = writeln!(y, "        name: {topic}");
        let _ = writeln!(y, "        type: {ty}");
        let _ = writeln!(y, "        serialization_format: cdr");
        let _ = writeln!(y, "        offered_qos_profiles: \"\"");
        let _ = writeln!(y, "        type_description_hash: {hash}");
        let _ = writeln!(y, "      message_count: {n}");
    }
    let _ = writeln!(y, "  compression_format: \"\"");
    let _ = writeln!(y, "  compression_mode: \"\"");
    let _ = writeln!(y, "  relative_file_paths:\n    - {file}");
    let _ = writeln!(y, "  files:");
    let _ = writeln!(y, "    - path: {file}");
    let _ = writeln!(
        y,
        "      starting_time:\n        nanoseconds_since_epoch: {start}"
    );
    let _ = writeln!(y, "      duration:\n        nanoseconds: {duration}");
    let _ = writeln!(y, "      message_count: {}", n * all.len() as u64);
    let _ = writeln!(y, "  custom_data: ~");
    let _ = writeln!(y, "  ros_distro: jazzy");
    let yaml = folder.join("metadata.yaml");
    crate::atomic::write_atomic(&yaml, y.as_bytes()).map_err(|e| WriteError::io(&yaml, e))?;
    Ok(written.bytes + y.len() as u64)
}
