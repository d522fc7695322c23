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
//! bag's last message (plus one grid period, the sample it stands for) to its first. A bag that
//! `export ros2` wrote carries its recording's labels, which are used instead (options given on
//! the command line win), and splits into the activations it came from. Written like
//! `import campaign`: a temporary folder renamed at the end; a failed import leaves nothing.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::log_terms::{in_log_terms, LogRows};
use drift_recording::ros2::{bag_files, read_bag, Bag, BagClock, BagTopics, ExportedActivation};
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
    /// Replace an earlier import in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// The `sensor_msgs/msg/Imu` topic: `angular_velocity`, rad/s.
    #[arg(long, default_value = "/imu/data")]
    pub gyro_topic: String,
    /// The `sensor_msgs/msg/Temperature` topic of the gyro's temperature sensor, °C (used for all
    /// three axes, unless the bag also has `<topic>/y` and `<topic>/z`, as `export ros2` writes).
    #[arg(long, default_value = "/imu/temperature")]
    pub temperature_topic: String,
    /// Message times: `header` (`header.stamp`, the driver's time of the measurement) or `log`
    /// (when the recorder received the message).
    #[arg(long, default_value = "header")]
    pub timestamps: String,
    /// Sample rate of the recording's grid, Hz (must divide 10⁹; default: the rate a bag written by
    /// `export ros2` says, else 100).
    #[arg(long)]
    pub rate_hz: Option<u32>,
    /// Interpolate onto a grid faster than the gyro messages come (refused otherwise: most
    /// samples would be made up).
    #[arg(long)]
    pub upsample: bool,
    /// Accept a temperature topic whose `header.frame_id` is not the gyro's.
    #[arg(long)]
    pub any_temperature_frame: bool,
    /// The longest step between gyro messages interpolated across, s.
    #[arg(long, default_value_t = 0.5)]
    pub max_gap: f64,
    /// The longest step between temperature messages interpolated across, s.
    #[arg(long, default_value_t = 5.0)]
    pub max_temperature_gap: f64,
    /// Unit id (default: the unit a bag written by `export ros2` says, else `ros2`).
    #[arg(long)]
    pub unit_id: Option<String>,
    /// Chamber (ambient) set point of every bag, °C (default: what a bag written by `export ros2`
    /// says, else each activation's first temperature).
    #[arg(long, allow_hyphen_values = true)]
    pub set_point: Option<f64>,
    /// Series kind of the bags: `protocol` or `field` (default: what a bag written by
    /// `export ros2` says, else `field`).
    #[arg(long)]
    pub series_kind: Option<String>,
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

/// One bag (or one activation of an exported bag), read and put on the grid.
pub(super) struct Activation {
    bag: PathBuf,
    files: Vec<PathBuf>,
    pub(super) segment: Segment,
    start_ns: i64,
    end_ns: i64,
    gyro_messages: usize,
    temperature_messages: usize,
    first_message: usize,
}

/// Reads one bag onto the grid of `options` (its rate, gap, unit, set point and kind), the
/// temperature interpolated across steps up to `max_temperature_gap` s; a grid faster than the
/// gyro messages is refused unless `upsample`.
pub(super) fn activation(
    bag: &Path,
    topics: &BagTopics,
    clock: BagClock,
    max_temperature_gap: f64,
    options: &CsvOptions,
    upsample: bool,
) -> anyhow::Result<Activation> {
    let files = bag_files(bag)?;
    let read = read_bag(bag, &files, topics, clock)?;
    on_grid(&read, files, max_temperature_gap, options, upsample)
}

/// Rates of the recording grid that divide 10⁹, fastest first: what `--rate-hz` may suggest.
const GRID_RATES: [u32; 14] = [
    1000, 800, 500, 400, 250, 200, 125, 100, 50, 40, 25, 20, 10, 5,
];

fn on_grid(
    read: &Bag,
    files: Vec<PathBuf>,
    max_temperature_gap: f64,
    options: &CsvOptions,
    upsample: bool,
) -> anyhow::Result<Activation> {
    let bag = &read.path;
    let topics = &read.topics;
    let rows = read.rows(max_temperature_gap)?;
    if rows.rows > 1 && !upsample {
        let message_hz = (rows.rows - 1) as f64 / ((rows.end_ns - rows.start_ns) as f64 * 1e-9);
        let grid = f64::from(options.sample_rate_hz);
        if grid > message_hz * 1.05 {
            let suggest = GRID_RATES
                .iter()
                .find(|&&r| f64::from(r) <= message_hz * 1.05)
                .copied()
                .unwrap_or(1);
            anyhow::bail!(
                "{}: topic {} has {message_hz:.1} messages per second, and a grid of {} Hz would make up {:.0} % of its samples by interpolation; give `--rate-hz {suggest}`, or `--upsample` to interpolate anyway",
                bag.display(),
                topics.gyro,
                options.sample_rate_hz,
                100.0 * (1.0 - message_hz / grid)
            );
        }
    }
    let field = |column: &str| match column {
        "gx" => "angular_velocity.x".to_owned(),
        "gy" => "angular_velocity.y".to_owned(),
        "gz" => "angular_velocity.z".to_owned(),
        "temp_c" => format!("{} temperature", topics.temperature),
        "temp_y" => format!("{}/y temperature", topics.temperature),
        "temp_z" => format!("{}/z temperature", topics.temperature),
        _ => "header.stamp".to_owned(),
    };
    let log_rows = LogRows {
        describe: format!(
            "{}: topic {} (temperature from {})",
            bag.display(),
            topics.gyro,
            topics.temperature
        ),
        first_message: rows.first_message as u64,
        field: &field,
    };
    let mut options = options.clone();
    options.columns.temperature_celsius = ["temp_c".into(), "temp_y".into(), "temp_z".into()];
    let recording = read_csv_bytes(Path::new(&log_rows.describe), rows.csv.as_bytes(), &options)
        .map_err(|e| in_log_terms(e, &log_rows))?;
    let segment = recording
        .segments
        .into_iter()
        .next()
        .with_context(|| format!("{}: no samples", log_rows.describe))?;
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

/// The activations of one bag: the bag itself (one power-on), or, for a bag `export ros2` wrote,
/// each activation its labels give with those labels and its switch-on time.
fn bag_activations(
    bag: &Path,
    topics: &BagTopics,
    clock: BagClock,
    args: &RosbagArgs,
    kind: SeriesKind,
) -> anyhow::Result<Vec<(Activation, Option<ExportedActivation>)>> {
    let files = bag_files(bag)?;
    let read = read_bag(bag, &files, topics, clock)?;
    let labels = read.labels.clone();
    let rate_hz = args
        .rate_hz
        .or(labels.as_ref().map(|l| l.sample_rate_hz))
        .unwrap_or(100);
    anyhow::ensure!(
        rate_hz > 0 && 1_000_000_000 % rate_hz == 0,
        "option `--rate-hz`: must divide 10⁹, got {rate_hz}"
    );
    let unit_id = args
        .unit_id
        .clone()
        .or(labels.as_ref().map(|l| l.unit_id.clone()))
        .unwrap_or_else(|| "ros2".into());
    let options = |set_point: Option<f64>, kind: SeriesKind| CsvOptions {
        unit_id: unit_id.clone(),
        ..super::import_ulog::log_options(rate_hz, args.max_gap, set_point, kind)
    };
    let Some(labels) = labels else {
        let options = options(args.set_point, kind);
        return Ok(vec![(
            on_grid(
                &read,
                files,
                args.max_temperature_gap,
                &options,
                args.upsample,
            )?,
            None,
        )]);
    };
    let period_ns = 1_000_000_000 / u64::from(labels.sample_rate_hz.max(1));
    let mut out = Vec::new();
    for exported in &labels.activations {
        let from = exported.power_on_ns;
        let to = from.saturating_add(exported.samples as u64 * period_ns);
        let part = read.between(
            i64::try_from(from).unwrap_or(i64::MAX),
            i64::try_from(to).unwrap_or(i64::MAX),
        );
        let kind = args
            .series_kind
            .as_ref()
            .map_or(exported.labels.series_kind, |_| kind);
        let set_point = args.set_point.or(Some(exported.labels.set_point_celsius));
        let activation = on_grid(
            &part,
            files.clone(),
            args.max_temperature_gap,
            &options(set_point, kind),
            args.upsample,
        )
        .with_context(|| {
            format!(
                "{}: activation {} of the exported recording",
                bag.display(),
                exported.labels.activation
            )
        })?;
        out.push((activation, Some(exported.clone())));
    }
    Ok(out)
}

/// Runs `gyrodrift import rosbag`.
pub fn run(args: &RosbagArgs) -> anyhow::Result<()> {
    let kind_given = args
        .series_kind
        .as_deref()
        .map(|k| {
            SeriesKind::parse(k).with_context(|| {
                format!("option `--series-kind`: expected `protocol` or `field`, got `{k}`")
            })
        })
        .transpose()?;
    let kind = kind_given.unwrap_or(SeriesKind::Field);
    let clock = match args.timestamps.as_str() {
        "header" => BagClock::Header,
        "log" => BagClock::Log,
        other => anyhow::bail!("option `--timestamps`: expected `header` or `log`, got `{other}`"),
    };
    if let Some(rate) = args.rate_hz {
        anyhow::ensure!(
            rate > 0 && 1_000_000_000 % rate == 0,
            "option `--rate-hz`: must divide 10⁹, got {rate}"
        );
    }
    super::campaign_out::refuse_existing(&args.out, args.force)?;
    let topics = BagTopics {
        gyro: args.gyro_topic.clone(),
        temperature: args.temperature_topic.clone(),
        any_temperature_frame: args.any_temperature_frame,
    };
    let mut activations = Vec::new();
    for bag in bags(&args.path)? {
        activations.extend(bag_activations(&bag, &topics, clock, args, kind)?);
    }
    activations.sort_by_key(|(a, _)| a.start_ns);
    let exported = activations.iter().all(|(_, e)| e.is_some());
    let rate_hz = activations
        .first()
        .map_or(100, |(a, _)| a.segment.sample_rate_hz);
    let unit_id = activations
        .first()
        .map_or_else(|| "ros2".into(), |(a, _)| a.segment.labels.unit_id.clone());
    let kind = activations
        .first()
        .map_or(kind, |(a, _)| a.segment.labels.series_kind);
    anyhow::ensure!(
        activations.iter().all(|(a, _)| a.segment.sample_rate_hz == rate_hz
            && a.segment.labels.unit_id == unit_id
            && a.segment.labels.series_kind == kind),
        "{}: the bags were exported from recordings of different units, rates or series kinds; import each recording's bags on its own",
        args.path.display()
    );
    let period_ns = i64::from(1_000_000_000 / rate_hz);
    let origin = activations.first().map_or(0, |(a, _)| a.start_ns);
    let mut listed = Vec::new();
    for k in 0..activations.len() {
        let off_before_s = match k.checked_sub(1).map(|j| &activations[j].0) {
            _ if exported => None,
            None => None,
            Some(before) => {
                let step_ns = activations[k].0.start_ns - before.end_ns;
                anyhow::ensure!(
                    step_ns as f64 * 1e-9 > args.max_gap,
                    "{} starts {:.6} s after the last message of {} (within `--max-gap` {} s, a step interpolated across): one bag is one power-on, and these overlap or follow each other without a power-off (a recording split into files); put the files of one power-on into one bag folder",
                    activations[k].0.bag.display(),
                    step_ns as f64 * 1e-9,
                    before.bag.display(),
                    args.max_gap
                );
                Some((step_ns - period_ns) as f64 / 1e9)
            }
        };
        let (a, from_export) = &mut activations[k];
        match from_export {
            Some(e) => {
                let set_point = a.segment.labels.set_point_celsius;
                a.segment.labels = e.labels.clone();
                a.segment.labels.unit_id = unit_id.clone();
                a.segment.labels.series_kind = kind;
                if args.set_point.is_some() {
                    a.segment.labels.set_point_celsius = set_point;
                    a.segment.labels.session_set_point_celsius = None;
                }
                a.segment.power_on_ns = e.power_on_ns;
            }
            None => {
                let labels = &mut a.segment.labels;
                labels.series = 1;
                labels.activation = u32::try_from(k + 1).unwrap_or(u32::MAX);
                labels.off_before_s = off_before_s;
                a.segment.power_on_ns = u64::try_from(a.start_ns - origin).unwrap_or(0);
            }
        }
        listed.push(serde_json::json!({
            "bag": a.bag.display().to_string(),
            "files": a.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
            "gyro_messages": a.gyro_messages,
            "temperature_messages": a.temperature_messages,
            "first_gyro_message_used": a.first_message,
            "start_ns": a.start_ns,
            "end_ns": a.end_ns,
            "off_before_s": a.segment.labels.off_before_s,
            "samples": a.segment.len(),
            "labels_from_export": from_export.is_some(),
        }));
    }
    // The recording's own set point: the option's, else the exported recording's.
    let set_point = args.set_point.or_else(|| {
        activations
            .first()
            .and_then(|(_, e)| e.as_ref())
            .map(|e| e.labels.nominal_set_point_celsius())
            .filter(|_| exported)
    });
    let clock_text = match clock {
        BagClock::Header => "header.stamp",
        BagClock::Log => "MCAP log time",
    };
    let metadata = [
        (
            "format_version",
            drift_recording::schema::FORMAT_VERSION.to_owned(),
        ),
        ("unit_id", unit_id.clone()),
        ("series_kind", kind.as_str().to_owned()),
        ("sample_rate_hz", rate_hz.to_string()),
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
    .chain(set_point.map(|s| ("set_point_celsius", format!("{s}"))))
    .map(|(k, v)| (k.to_owned(), v))
    .collect();
    let recording = Recording {
        path: PathBuf::new(),
        metadata,
        unit_id: unit_id.clone(),
        sample_rate_hz: rate_hz,
        segments: activations.into_iter().map(|(a, _)| a.segment).collect(),
    };
    let stem = unit_id
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
        "sample_rate_hz": rate_hz,
        "max_gap_s": args.max_gap,
        "max_temperature_gap_s": args.max_temperature_gap,
        "off_times": if exported {
            "the labels `export ros2` wrote into the bags"
        } else if listed.len() > 1 {
            "from the bags' times: each bag's first message less the previous bag's last message and one grid period"
        } else {
            "unknown: one bag is one power-on"
        },
        "bags": listed,
    });
    let lines = super::campaign_out::write_campaign(
        &args.out,
        args.force,
        &[(stem, recording)],
        &manifest,
    )?;
    for line in lines {
        println!("{line}");
    }
    Ok(())
}
