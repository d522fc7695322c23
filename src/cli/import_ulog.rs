//! `gyrodrift import ulog`: PX4 ULog files → a campaign folder.
//!
//! Every `sensor_gyro` instance of a log is a unit (`<unit-id>-gyro<instance>`) with its own
//! `temperature`; a log without `sensor_gyro` falls back to `sensor_combined` (one unit
//! `<unit-id>-combined`, rates `gyro_rad[0..2]`, and the barometer's `baro_temp_celcius` as its only
//! temperature, which older logs carry). One log is one power-on: one activation. A folder of logs
//! (sorted by name) is one series per unit; ULog has no wall clock in its header, so the off-time
//! between logs is unknown (stated in `import.json`), and the activations are laid out 1 s apart.
//! The messages' boot-time timestamps (µs) are interpolated linearly onto the `--rate-hz` grid, as
//! `import csv --timing resample` does (a step longer than `--max-gap` is an error naming the log,
//! the topic and the message). Written like `import campaign`: a temporary folder renamed at the
//! end; a failed import leaves nothing.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;

use super::log_terms::{in_log_terms, LogRows};
use drift_recording::ulog::{read_ulog, Ulog, UlogTopic};
use drift_recording::{
    read_csv_bytes, CsvColumns, CsvOptions, CsvTiming, RateUnit, Recording, Segment, SeriesKind,
    RAW_PER_CELSIUS,
};

/// Options of `gyrodrift import ulog`.
#[derive(Debug, clap::Args)]
pub struct UlogArgs {
    /// A `.ulg` file, or a folder of them (one series, in name order).
    pub path: PathBuf,
    /// Output: a new campaign folder (`recordings/<unit>.mcap`, `import.json`).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Replace an earlier import in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// Import a log the file's end cuts inside a message (its complete messages before the cut).
    #[arg(long)]
    pub truncated: bool,
    /// Interpolate onto a grid faster than the gyro messages come.
    #[arg(long)]
    pub upsample: bool,
    /// Sample rate of the recording's grid, Hz (must divide 10⁹).
    #[arg(long, default_value_t = 100)]
    pub rate_hz: u32,
    /// The longest step between messages interpolated across, s.
    #[arg(long, default_value_t = 0.5)]
    pub max_gap: f64,
    /// Unit id prefix.
    #[arg(long, default_value = "px4")]
    pub unit_id: String,
    /// Chamber (ambient) set point of every log, °C (default: each activation's first
    /// temperature).
    #[arg(long, allow_hyphen_values = true)]
    pub set_point: Option<f64>,
    /// Series kind of the logs: `protocol` or `field`.
    #[arg(long, default_value = "field")]
    pub series_kind: String,
}

/// The gyro topics of a log: (unit suffix, topic, rate fields, temperature field).
pub(super) fn gyros(log: &Ulog) -> Vec<(String, &UlogTopic, [&'static str; 3], &'static str)> {
    let gyro = log.topic("sensor_gyro");
    if !gyro.is_empty() {
        return gyro
            .into_iter()
            .filter(|t| !t.is_empty())
            .map(|t| {
                (
                    format!("gyro{}", t.instance),
                    t,
                    ["x", "y", "z"],
                    "temperature",
                )
            })
            .collect();
    }
    log.topic("sensor_combined")
        .into_iter()
        .filter(|t| !t.is_empty())
        .map(|t| {
            (
                format!("combined{}", t.instance),
                t,
                ["gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]"],
                "baro_temp_celcius",
            )
        })
        .collect()
}

/// One topic instance of one log as CSV text (time s, rates rad/s, temperature °C), read back by
/// the CSV reader with resampling: one activation.
pub(super) fn activation(
    log: &Ulog,
    topic: &UlogTopic,
    rates: [&str; 3],
    temperature: &str,
    options: &CsvOptions,
) -> anyhow::Result<Segment> {
    let field = |name: &str| {
        topic.values(name).with_context(|| {
            format!(
                "{}: `{}` instance {} has no field `{name}` (it has: {})",
                log.path.display(),
                topic.name,
                topic.instance,
                topic.field_names().collect::<Vec<_>>().join(", ")
            )
        })
    };
    let t = field("timestamp")?;
    let r = [field(rates[0])?, field(rates[1])?, field(rates[2])?];
    let c = field(temperature)?;
    let mut text = String::from("t_s,gx,gy,gz,temp_c\n");
    for i in 0..t.len() {
        writeln!(
            text,
            "{},{},{},{},{}",
            t[i] * 1e-6,
            r[0][i],
            r[1][i],
            r[2][i],
            c[i]
        )?;
    }
    let describe = format!(
        "{}: topic `{}` instance {}",
        log.path.display(),
        topic.name,
        topic.instance
    );
    let field = |column: &str| match column {
        "gx" => rates[0].to_owned(),
        "gy" => rates[1].to_owned(),
        "gz" => rates[2].to_owned(),
        "temp_c" => temperature.to_owned(),
        _ => "timestamp".to_owned(),
    };
    let rows = LogRows {
        describe,
        first_message: 1,
        field: &field,
    };
    let recording = read_csv_bytes(Path::new(&rows.describe), text.as_bytes(), options)
        .map_err(|e| in_log_terms(e, &rows))?;
    recording
        .segments
        .into_iter()
        .next()
        .with_context(|| format!("{}: no samples", rows.describe))
}

fn logs(path: &Path) -> anyhow::Result<Vec<PathBuf>> {
    if !path.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(path)
        .with_context(|| format!("listing {}", path.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ulg"))
        .collect();
    files.sort();
    anyhow::ensure!(!files.is_empty(), "{}: no .ulg files", path.display());
    Ok(files)
}

/// How a flight or robot log's messages become one activation's samples (shared with
/// `import rosbag`): the gyro in rad/s as columns `gx gy gz`, resampled onto the output grid with
/// gaps up to `max_gap_s`.
pub(super) fn log_options(
    sample_rate_hz: u32,
    max_gap_s: f64,
    set_point_celsius: Option<f64>,
    series_kind: SeriesKind,
) -> CsvOptions {
    CsvOptions {
        columns: CsvColumns {
            rate_dps: ["gx".into(), "gy".into(), "gz".into()],
            segment: None,
            ..CsvColumns::default()
        },
        sample_rate_hz,
        timing: CsvTiming::Resample { max_gap_s },
        set_point_celsius,
        series_kind,
        rate_unit: RateUnit::RadPerSec,
        ..CsvOptions::default()
    }
}

/// Refuses a log whose end cuts a message (the logger stopped midway, or the copy is short)
/// unless `accept`: its time span would silently end early.
pub fn refuse_cut(log: &Ulog, accept: bool) -> anyhow::Result<()> {
    if let (Some(cut), false) = (log.cut_at, accept) {
        let length = std::fs::metadata(&log.path).map_or(0, |m| m.len());
        anyhow::bail!(
            "{}: the log ends inside a message at byte {cut} of {length}: the file is truncated (the logger stopped midway, or the copy is short) and whatever followed is missing; give the whole log, or `--truncated` to import the complete messages before the cut",
            log.path.display()
        );
    }
    Ok(())
}

/// Runs `gyrodrift import ulog`.
pub fn run(args: &UlogArgs) -> anyhow::Result<()> {
    let kind = SeriesKind::parse(&args.series_kind).with_context(|| {
        format!(
            "option `--series-kind`: expected `protocol` or `field`, got `{}`",
            args.series_kind
        )
    })?;
    let options = log_options(args.rate_hz, args.max_gap, args.set_point, kind);
    super::campaign_out::refuse_existing(&args.out, args.force)?;
    let files = logs(&args.path)?;
    let mut units: BTreeMap<String, Vec<Segment>> = BTreeMap::new();
    let mut read = Vec::new();
    for (k, file) in files.iter().enumerate() {
        let log = read_ulog(file)?;
        refuse_cut(&log, args.truncated)?;
        let topics = gyros(&log);
        anyhow::ensure!(
            !topics.is_empty(),
            "{}: no `sensor_gyro` or `sensor_combined` data",
            file.display()
        );
        let mut instances = Vec::new();
        for (suffix, topic, rates, temperature) in topics {
            let unit = format!("{}-{suffix}", args.unit_id);
            let mut segment = activation(&log, topic, rates, temperature, &options)?;
            let what = format!("`{}` instance {} messages", topic.name, topic.instance);
            super::row_use::refuse_made_up_or_dropped(
                file,
                super::row_use::RowUse {
                    rows: topic.len(),
                    what: &what,
                    samples: segment.len(),
                    rate_hz: args.rate_hz,
                    time_unit: None,
                },
                args.upsample,
                true,
            )?;
            segment.labels.unit_id = unit.clone();
            segment.labels.series = 1;
            segment.labels.activation = u32::try_from(k + 1).unwrap_or(u32::MAX);
            let series = units.entry(unit.clone()).or_default();
            let period_ns = 1_000_000_000 / u64::from(args.rate_hz.max(1));
            segment.power_on_ns = series.last().map_or(0, |s| {
                s.power_on_ns + s.len() as u64 * period_ns + 1_000_000_000
            });
            instances.push(serde_json::json!({
                "unit": unit,
                "topic": topic.name,
                "instance": topic.instance,
                "messages": topic.len(),
                "samples": segment.len(),
            }));
            series.push(segment);
        }
        read.push(serde_json::json!({ "log": file.display().to_string(), "start_us": log.start_us, "units": instances }));
    }
    let recordings: Vec<(String, Recording)> = units
        .into_iter()
        .map(|(unit, segments)| {
            let metadata = [
                ("format_version", drift_recording::schema::FORMAT_VERSION.to_owned()),
                ("unit_id", unit.clone()),
                ("series_kind", kind.as_str().to_owned()),
                ("sample_rate_hz", args.rate_hz.to_string()),
                ("temperature_raw_per_celsius", format!("{RAW_PER_CELSIUS}")),
                ("source", format!("ulog: {}", args.path.display())),
                (
                    "clock",
                    "one log per activation, laid out 1 s apart: the off-time between logs is unknown".to_owned(),
                ),
            ]
            .into_iter()
            .chain(args.set_point.map(|s| ("set_point_celsius", format!("{s}"))))
            .map(|(k, v)| (k.to_owned(), v))
            .collect();
            let recording = Recording {
                path: PathBuf::new(),
                metadata,
                unit_id: unit.clone(),
                sample_rate_hz: args.rate_hz,
                segments,
            };
            (unit, recording)
        })
        .collect();
    let manifest = serde_json::json!({
        "source": args.path.display().to_string(),
        "sample_rate_hz": args.rate_hz,
        "max_gap_s": args.max_gap,
        "off_times": "unknown: ULog headers carry boot time, not wall-clock time",
        "logs": read,
    });
    let lines = super::campaign_out::write_campaign(&args.out, args.force, &recordings, &manifest)?;
    for line in lines {
        println!("{line}");
    }
    Ok(())
}
