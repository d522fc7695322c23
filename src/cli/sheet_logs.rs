//! The activation files of `import campaign` that are logs of another tool: a ROS 2 bag (an
//! `.mcap` file or a bag folder) or a PX4 ULog (`.ulg`), read as `import rosbag` and `import ulog`
//! read them, one log per activation; the sheet gives the labels.

use std::path::Path;

use anyhow::Context;
use drift_recording::ros2::{BagClock, BagTopics};
use drift_recording::ulog::read_ulog;
use drift_recording::{CsvOptions, Segment};

/// How logs named by the sheet are read.
#[derive(Debug, clap::Args)]
pub struct LogArgs {
    /// Bags: the `sensor_msgs/msg/Imu` topic (`angular_velocity`, rad/s).
    #[arg(long, default_value = "/imu/data")]
    pub gyro_topic: String,
    /// Bags: the `sensor_msgs/msg/Temperature` topic of the gyro's temperature sensor, °C.
    #[arg(long, default_value = "/imu/temperature")]
    pub temperature_topic: String,
    /// Bags: message times, `header` (`header.stamp`) or `log` (the recorder's receive time).
    #[arg(long, default_value = "header")]
    pub timestamps: String,
    /// Bags: the longest step between temperature messages interpolated across, s.
    #[arg(long, default_value_t = 5.0)]
    pub max_temperature_gap: f64,
    /// Bags: accept a temperature topic whose `header.frame_id` is not the gyro's.
    #[arg(long)]
    pub any_temperature_frame: bool,
    /// Bags: interpolate onto a grid faster than the gyro messages come.
    #[arg(long)]
    pub upsample: bool,
    /// ULog files: import a log the file's end cuts inside a message.
    #[arg(long)]
    pub truncated: bool,
    /// ULog files with several gyros: the `sensor_gyro` instance to read.
    #[arg(long)]
    pub ulog_instance: Option<u8>,
}

/// What a file named by the sheet is.
enum Kind {
    Bag,
    Ulog,
    Csv,
}

fn kind(path: &Path) -> Kind {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if path.is_dir() || ext.eq_ignore_ascii_case("mcap") {
        Kind::Bag
    } else if ext.eq_ignore_ascii_case("ulg") {
        Kind::Ulog
    } else {
        Kind::Csv
    }
}

impl LogArgs {
    /// The clock option, checked.
    pub fn clock(&self) -> anyhow::Result<BagClock> {
        match self.timestamps.as_str() {
            "header" => Ok(BagClock::Header),
            "log" => Ok(BagClock::Log),
            other => {
                anyhow::bail!("option `--timestamps`: expected `header` or `log`, got `{other}`")
            }
        }
    }

    /// Reads `path` if it is a log (a bag or a ULog) onto the grid of `csv` (the sheet's rate;
    /// the row's unit, set point and kind), interpolating across steps up to `max_gap_s`; `None`
    /// for a CSV file.
    pub fn read(
        &self,
        path: &Path,
        csv: &CsvOptions,
        clock: BagClock,
        max_gap_s: f64,
    ) -> Option<anyhow::Result<Segment>> {
        let options = CsvOptions {
            unit_id: csv.unit_id.clone(),
            ..super::import_ulog::log_options(
                csv.sample_rate_hz,
                max_gap_s,
                csv.set_point_celsius,
                csv.series_kind,
            )
        };
        match kind(path) {
            Kind::Csv => None,
            Kind::Bag => {
                let topics = BagTopics {
                    gyro: self.gyro_topic.clone(),
                    temperature: self.temperature_topic.clone(),
                    any_temperature_frame: self.any_temperature_frame,
                };
                Some(
                    super::import_rosbag::activation(
                        path,
                        &topics,
                        clock,
                        self.max_temperature_gap,
                        &options,
                        self.upsample,
                    )
                    .map(|a| a.segment),
                )
            }
            Kind::Ulog => Some(self.read_ulog(path, &options)),
        }
    }

    fn read_ulog(&self, path: &Path, options: &CsvOptions) -> anyhow::Result<Segment> {
        let log = read_ulog(path)?;
        super::import_ulog::refuse_cut(&log, self.truncated)?;
        let gyros = super::import_ulog::gyros(&log);
        let chosen: Vec<_> = gyros
            .iter()
            .filter(|(_, topic, _, _)| self.ulog_instance.is_none_or(|i| topic.instance == i))
            .collect();
        let names = || {
            gyros
                .iter()
                .map(|(_, t, _, _)| format!("{} instance {}", t.name, t.instance))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (_, topic, rates, temperature) = match chosen.as_slice() {
            [one] => one,
            [] if gyros.is_empty() => {
                anyhow::bail!(
                    "{}: no `sensor_gyro` or `sensor_combined` data",
                    path.display()
                )
            }
            [] => anyhow::bail!(
                "{}: no gyro instance {} (the log has {}); choose one with `--ulog-instance`",
                path.display(),
                self.ulog_instance.unwrap_or_default(),
                names()
            ),
            _ => anyhow::bail!(
                "{}: {} gyros ({}); a sheet row is one unit: choose one with `--ulog-instance`",
                path.display(),
                chosen.len(),
                names()
            ),
        };
        super::import_ulog::activation(&log, topic, *rates, temperature, options)
            .with_context(|| format!("{}: reading the gyro", path.display()))
    }
}
