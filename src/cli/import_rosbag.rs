//! `gyrodrift import rosbag`: ROS 2 bags (rosbag2's MCAP storage) → a campaign folder.
//!
//! The gyro topic (`sensor_msgs/msg/Imu`, `angular_velocity` in rad/s) and the temperature topic
//! (`sensor_msgs/msg/Temperature`, °C) are named by option; each message is timed by its
//! `header.stamp` (or, with `--timestamps log`, by the recorder's log time). The temperature is
//! interpolated linearly at each gyro message (gyro messages outside the temperature topic's span
//! are left out), and the messages are interpolated onto the `--rate-hz` grid as `import csv
//! --timing resample` does (a step longer than `--max-gap` is an error naming the bag, the topic
//! and the message). One bag is one power-on: one activation. A folder of bags is one series in
//! order of the bags' start times, each activation's off-time before it the time from the previous
//! bag's last message (plus one grid period, the sample it stands for) to its first. Written like
//! `import campaign`: a temporary folder renamed at the end; a failed import leaves nothing.

use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_recording::ros2::{bag_files, read_bag, BagClock, BagTopics};
use drift_recording::{
    read_csv_bytes, CsvOptions, Recording, Segment, SeriesKind, RAW_PER_CELSIUS,
};

/// Options of `gyrodrift import rosbag`.
#[derive(Debug, clap::Args)]
pub struct RosbagArgs {
    /// A bag: an `.mcap` file or a bag folder (`metadata.yaml` and its `.mcap` files); or a folder
    /// of bags (one series, in order of their start times).
    pub path: PathBuf,
    /// Output: a new campaign folder (`recordings/<unit>.mcap`, `import.json`).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// The `sensor_msgs/msg/Imu` topic: `angular_velocity`, rad/s.
    #[arg(long, default_value = "/imu/data")]
    pub gyro_topic: String,
    /// The `sensor_msgs/msg/Temperature` topic of the gyro's temperature sensor, °C (used for all
    /// three axes).
    #[arg(long, default_value = "/imu/temperature")]
    pub temperature_topic: String,
    /// Message times: `header` (`header.stamp`, the driver's time of the measurement) or `log`
    /// (when the recorder received the message).
    #[arg(long, default_value = "header")]
    pub timestamps: String,
    /// Sample rate of the recording's grid, Hz (must divide 10⁹).
    #[arg(long, default_value_t = 100)]
    pub rate_hz: u32,
    /// The longest step between gyro messages interpolated across, s.
    #[arg(long, default_value_t = 0.5)]
    pub max_gap: f64,
    /// The longest step between temperature messages interpolated across, s.
    #[arg(long, default_value_t = 5.0)]
    pub max_temperature_gap: f64,
    /// Unit id.
    #[arg(long, default_value = "ros2")]
    pub unit_id: String,
    /// Chamber (ambient) set point of every bag, °C (default: each activation's first
    /// temperature).
    #[arg(long, allow_hyphen_values = true)]
    pub set_point: Option<f64>,
    /// Series kind of the bags: `protocol` or `field`.
    #[arg(long, default_value = "field")]
    pub series_kind: String,
}

fn is_bag_folder(path: &Path) -> bool {
    path.join("metadata.yaml").is_file()
}

/// The bags under `path`: the file or bag folder itself, or each `.mcap` file and bag folder
/// (a folder with `metadata.yaml`, or with `.mcap` files) directly inside it.
fn bags(path: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if !path.is_dir() || is_bag_folder(path) {
        return Ok(vec![path.to_path_buf()]);
    }
    let mut found: Vec<PathBuf> = std::fs::read_dir(path)
        .with_context(|| format!("listing {}", path.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        })
        .filter(|p| {
            if p.is_dir() {
                is_bag_folder(p) || bag_files(p).is_ok()
            } else {
                p.extension().is_some_and(|e| e == "mcap")
            }
        })
        .collect();
    found.sort();
    anyhow::ensure!(
        !found.is_empty(),
        "{}: no bags (`.mcap` files, or bag folders with `metadata.yaml`)",
        path.display()
    );
    Ok(found)
}

/// One bag, read and put on the grid.
struct Activation {
    bag: PathBuf,
    files: Vec<PathBuf>,
    segment: Segment,
    start_ns: i64,
    end_ns: i64,
    gyro_messages: usize,
    temperature_messages: usize,
    first_message: usize,
}

fn activation(
    bag: &Path,
    topics: &BagTopics,
    clock: BagClock,
    args: &RosbagArgs,
    options: &CsvOptions,
) -> anyhow::Result<Activation> {
    let files = bag_files(bag)?;
    let read = read_bag(bag, &files, topics, clock)?;
    let rows = read.rows(args.max_temperature_gap)?;
    let name = PathBuf::from(format!(
        "{} ({} from message #{}, row = message; temperature from {})",
        bag.display(),
        topics.gyro,
        rows.first_message,
        topics.temperature
    ));
    let recording = read_csv_bytes(&name, rows.csv.as_bytes(), options)?;
    let segment = recording
        .segments
        .into_iter()
        .next()
        .with_context(|| format!("{}: no samples", name.display()))?;
    Ok(Activation {
        bag: bag.to_path_buf(),
        files,
        segment,
        start_ns: rows.start_ns,
        end_ns: rows.end_ns,
        gyro_messages: read.gyro.len(),
        temperature_messages: read.temperature.len(),
        first_message: rows.first_message,
    })
}

/// Runs `gyrodrift import rosbag`.
pub fn run(args: &RosbagArgs) -> anyhow::Result<()> {
    let kind = SeriesKind::parse(&args.series_kind).with_context(|| {
        format!(
            "option `--series-kind`: expected `protocol` or `field`, got `{}`",
            args.series_kind
        )
    })?;
    let clock = match args.timestamps.as_str() {
        "header" => BagClock::Header,
        "log" => BagClock::Log,
        other => anyhow::bail!("option `--timestamps`: expected `header` or `log`, got `{other}`"),
    };
    anyhow::ensure!(
        args.rate_hz > 0 && 1_000_000_000 % args.rate_hz == 0,
        "option `--rate-hz`: must divide 10⁹, got {}",
        args.rate_hz
    );
    let options = CsvOptions {
        unit_id: args.unit_id.clone(),
        ..super::import_ulog::log_options(args.rate_hz, args.max_gap, args.set_point, kind)
    };
    super::import_campaign::refuse_existing(&args.out)?;
    let topics = BagTopics {
        gyro: args.gyro_topic.clone(),
        temperature: args.temperature_topic.clone(),
    };
    let mut activations = bags(&args.path)?
        .iter()
        .map(|bag| activation(bag, &topics, clock, args, &options))
        .collect::<anyhow::Result<Vec<_>>>()?;
    activations.sort_by_key(|a| a.start_ns);
    let period_ns = i64::from(1_000_000_000 / args.rate_hz);
    let origin = activations.first().map_or(0, |a| a.start_ns);
    let mut listed = Vec::new();
    for k in 0..activations.len() {
        let off_before_s = match k.checked_sub(1).map(|j| &activations[j]) {
            None => None,
            Some(before) => {
                let off_ns = activations[k].start_ns - before.end_ns - period_ns;
                anyhow::ensure!(
                    off_ns > 0,
                    "{} starts {:.6} s after the last message of {}, within one sample period ({} s at --rate-hz {}): one bag is one power-on, and these overlap or follow each other without a power-off; put the files of one power-on into one bag folder",
                    activations[k].bag.display(),
                    (activations[k].start_ns - before.end_ns) as f64 * 1e-9,
                    before.bag.display(),
                    1.0 / f64::from(args.rate_hz),
                    args.rate_hz
                );
                Some(off_ns as f64 / 1e9)
            }
        };
        let a = &mut activations[k];
        let labels = &mut a.segment.labels;
        labels.unit_id = args.unit_id.clone();
        labels.series = 1;
        labels.activation = u32::try_from(k + 1).unwrap_or(u32::MAX);
        labels.off_before_s = off_before_s;
        a.segment.power_on_ns = u64::try_from(a.start_ns - origin).unwrap_or(0);
        listed.push(serde_json::json!({
            "bag": a.bag.display().to_string(),
            "files": a.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
            "gyro_messages": a.gyro_messages,
            "temperature_messages": a.temperature_messages,
            "first_gyro_message_used": a.first_message,
            "start_ns": a.start_ns,
            "end_ns": a.end_ns,
            "off_before_s": off_before_s,
            "samples": a.segment.len(),
        }));
    }
    let clock_text = match clock {
        BagClock::Header => "header.stamp",
        BagClock::Log => "MCAP log time",
    };
    let metadata = [
        (
            "format_version",
            drift_recording::schema::FORMAT_VERSION.to_owned(),
        ),
        ("unit_id", args.unit_id.clone()),
        ("series_kind", kind.as_str().to_owned()),
        ("sample_rate_hz", args.rate_hz.to_string()),
        ("temperature_raw_per_celsius", format!("{RAW_PER_CELSIUS}")),
        ("source", format!("rosbag: {}", args.path.display())),
        (
            "clock",
            format!(
                "ns since the first bag's first message ({clock_text}); one bag per activation"
            ),
        ),
    ]
    .into_iter()
    .chain(
        args.set_point
            .map(|s| ("set_point_celsius", format!("{s}"))),
    )
    .map(|(k, v)| (k.to_owned(), v))
    .collect();
    let recording = Recording {
        path: PathBuf::new(),
        metadata,
        unit_id: args.unit_id.clone(),
        sample_rate_hz: args.rate_hz,
        segments: activations.into_iter().map(|a| a.segment).collect(),
    };
    let stem = args
        .unit_id
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect::<String>();
    let manifest = serde_json::json!({
        "source": args.path.display().to_string(),
        "gyro_topic": args.gyro_topic,
        "temperature_topic": args.temperature_topic,
        "timestamps": clock_text,
        "sample_rate_hz": args.rate_hz,
        "max_gap_s": args.max_gap,
        "max_temperature_gap_s": args.max_temperature_gap,
        "off_times": if listed.len() > 1 {
            "from the bags' times: each bag's first message less the previous bag's last message and one grid period"
        } else {
            "unknown: one bag is one power-on"
        },
        "bags": listed,
    });
    let lines = super::import_campaign::write_campaign(&args.out, &[(stem, recording)], &manifest)?;
    for line in lines {
        println!("{line}");
    }
    Ok(())
}
