//! Writing a recording's activations as a ROS 2 bag: one standard message per sample.

use std::path::Path;

use super::definitions::{
    IMU_DEFINITION, IMU_SCHEMA, PROFILE_ROS2, TEMPERATURE_DEFINITION, TEMPERATURE_SCHEMA,
};
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

/// Writes `segments` (one unit's activations) as a ROS 2 bag file (rosbag2's MCAP storage,
/// profile `ros2`): per sample one `sensor_msgs/msg/Imu` on `topics.imu` (`angular_velocity` in
/// rad/s; no orientation or acceleration estimate: element 0 of their covariances is −1) and one
/// `sensor_msgs/msg/Temperature` per axis (°C, NaN for a missing reading), with `header.stamp` =
/// log time = the sample's time on the recording clock and `header.frame_id` = `frame_id`.
/// Written through a temporary file renamed at the end; returns the bytes written.
pub fn write_ros2_bag(
    path: &Path,
    segments: &[&Segment],
    frame_id: &str,
    topics: &ExportTopics,
) -> Result<u64, WriteError> {
    let invalid = |reason: String| WriteError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let mut f = McapFile::create(path, PROFILE_ROS2, mcap::Compression::Zstd)?;
    f.add_topic(&topics.imu, (IMU_SCHEMA, IMU_DEFINITION), &[])?;
    let temperature_topics = topics.temperature_axes();
    for topic in &temperature_topics {
        f.add_topic(topic, (TEMPERATURE_SCHEMA, TEMPERATURE_DEFINITION), &[])?;
    }
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
    f.finish()
}
