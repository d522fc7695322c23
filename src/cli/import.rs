//! `gyrodrift import csv`: measured data (CSV, plain or gzip) → an MCAP recording that `fit`,
//! `report` and `diagnose` read.
//!
//! The output is either one `.mcap` file or a campaign folder: `<out>/recordings/<unit>_<stem>.mcap`
//! and `<out>/import.json` (the source, the options and what was read). The CSV is read and
//! validated completely before anything is written (errors name the file, the row and the column);
//! the MCAP file is written to a temporary sibling and renamed, the manifest with `write_atomic`.

use std::path::{Path, PathBuf};

use drift_recording::{read_csv, write_recording, CsvOptions, SeriesKind, RECORDINGS_DIR};

use drift_report::write_atomic;

use super::campaign_out::WRITER;
use super::reading::ReadingArgs;

/// Options of `gyrodrift import`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The source format.
    #[command(subcommand)]
    pub format: Format,
}

/// Source formats.
#[derive(Debug, clap::Subcommand)]
pub enum Format {
    /// CSV with a header row (gzip-compressed if the name ends in `.gz`).
    Csv(CsvArgs),
    /// A bench campaign: one CSV file (plain or `.gz`) per activation and an activation sheet.
    Campaign(super::import_campaign::CampaignArgs),
    /// PX4 ULog files (`.ulg`): a file, or a folder of them as one series.
    Ulog(super::import_ulog::UlogArgs),
    /// ROS 2 bags (rosbag2's MCAP storage) with `sensor_msgs/msg/Imu` and
    /// `sensor_msgs/msg/Temperature` topics: a bag (file or folder), or a folder of bags as one
    /// series.
    #[command(visible_alias = "ros2")]
    Rosbag(super::import_rosbag::RosbagArgs),
}

/// Options of `gyrodrift import csv`.
#[derive(Debug, clap::Args)]
pub struct CsvArgs {
    /// The CSV file.
    pub file: PathBuf,
    /// Output: a `.mcap` file, or a campaign folder (gets `recordings/<unit>_<stem>.mcap` and
    /// `import.json`; it must not exist or be empty, or hold an earlier import and `--force`).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Replace an earlier import in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// Column mapping, units and timing.
    #[command(flatten)]
    pub reading: ReadingArgs,
    /// Activation column: consecutive rows with one value are one activation.
    #[arg(
        long,
        default_value = "segment_id",
        conflicts_with = "no_segment_column"
    )]
    pub segment_column: String,
    /// The whole file is one activation (no activation column).
    #[arg(long)]
    pub no_segment_column: bool,
    /// Unit id written into the recording.
    #[arg(long, default_value = "csv")]
    pub unit_id: String,
    /// Chamber set point of every activation, °C (default: each activation's first temperature).
    #[arg(long, allow_hyphen_values = true)]
    pub set_point: Option<f64>,
    /// Series kind of every activation: `protocol` or `field`.
    #[arg(long, default_value = "protocol")]
    pub series_kind: String,
    /// With `--timing resample`: interpolate onto a grid faster than the rows come.
    #[arg(long)]
    pub upsample: bool,
    /// With `--timing resample`: keep a grid much slower than the rows, leaving most rows unused.
    #[arg(long)]
    pub downsample: bool,
}

impl CsvArgs {
    /// The reader's options, with each bad value named by its option.
    pub fn options(&self) -> anyhow::Result<CsvOptions> {
        let mut options = self.reading.options()?;
        options.columns.segment = (!self.no_segment_column).then(|| self.segment_column.clone());
        options.unit_id = self.unit_id.clone();
        options.set_point_celsius = self.set_point;
        options.series_kind = SeriesKind::parse(&self.series_kind).ok_or_else(|| {
            anyhow::anyhow!(
                "option `--series-kind`: expected `protocol` or `field`, got `{}`",
                self.series_kind
            )
        })?;
        Ok(options)
    }
}

/// A file-name-safe version of `text` (letters, digits, `-`, `_`, `.`; anything else `_`).
fn file_safe(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Where the recording goes: `out` itself if it names a `.mcap` file, else inside the campaign
/// folder `out`; and the manifest's path for a campaign folder.
pub fn destination(out: &Path, unit_id: &str, source: &Path) -> (PathBuf, Option<PathBuf>) {
    if out.extension().is_some_and(|e| e == "mcap") {
        return (out.to_path_buf(), None);
    }
    let name = source
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name
        .trim_end_matches(".gz")
        .trim_end_matches(".csv")
        .to_owned();
    let file = format!("{}_{}.mcap", file_safe(unit_id), file_safe(&stem));
    (
        out.join(RECORDINGS_DIR).join(file),
        Some(out.join("import.json")),
    )
}

/// Runs `gyrodrift import`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.format {
        Format::Csv(csv) => run_csv(csv),
        Format::Campaign(campaign) => super::import_campaign::run(campaign),
        Format::Ulog(ulog) => super::import_ulog::run(ulog),
        Format::Rosbag(rosbag) => super::import_rosbag::run(rosbag),
    }
}

fn run_csv(args: &CsvArgs) -> anyhow::Result<()> {
    let options = args.options()?;
    let (mcap, manifest) = destination(&args.out, &args.unit_id, &args.file);
    if manifest.is_some() {
        super::campaign_out::refuse_existing(&args.out, args.force)?;
    }
    // Read and validate everything first: an error leaves the output untouched.
    let recording = read_csv(&args.file, &options)?;
    let samples: usize = recording.segments.iter().map(|s| s.len()).sum();
    let fs = f64::from(recording.sample_rate_hz);
    let rows: usize = recording
        .metadata
        .get("csv_rows")
        .and_then(|r| r.parse().ok())
        .unwrap_or(samples);
    super::row_use::refuse_made_up_or_dropped(
        &args.file,
        super::row_use::RowUse {
            rows,
            what: "rows",
            samples,
            rate_hz: recording.sample_rate_hz,
            time_unit: Some(&args.reading.time_unit),
        },
        args.upsample,
        args.downsample,
    )?;
    let activations: Vec<serde_json::Value> = recording
        .segments
        .iter()
        .map(|s| {
            serde_json::json!({
                "series": s.labels.series,
                "samples": s.len(),
                "duration_s": s.len() as f64 / fs,
                "set_point_celsius": s.labels.set_point_celsius,
                "aux": s.aux.iter().map(|(k, c)| (k.clone(), c.values.len())).collect::<std::collections::BTreeMap<_, _>>(),
            })
        })
        .collect();
    let manifest_json = serde_json::json!({
        "source": args.file.display().to_string(),
        "recording": mcap.display().to_string(),
        "unit_id": recording.unit_id,
        "sample_rate_hz": recording.sample_rate_hz,
        "samples": samples,
        "metadata": recording.metadata,
        "activations": activations,
    });
    let manifest_bytes = serde_json::to_string_pretty(&manifest_json)?;
    let bytes = match &manifest {
        None => write_recording(&recording, &mcap)?,
        Some(_) => {
            // A campaign folder is written whole, as every import's is: never added to.
            let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
            let (staged_mcap, staged_manifest) =
                destination(staged.path(), &args.unit_id, &args.file);
            let bytes = write_recording(&recording, &staged_mcap)?;
            if let Some(path) = &staged_manifest {
                write_atomic(path, manifest_bytes.as_bytes())?;
            }
            staged.commit()?;
            bytes
        }
    };
    let meta = |key: &str| recording.metadata.get(key).cloned().unwrap_or_default();
    println!(
        "{}: {} rows → {} activations, {samples} samples at {} Hz ({:.1} s); longest step between rows {} s, {} steps over two periods ({} s); {bytes} bytes → {}",
        args.file.display(),
        meta("csv_rows"),
        recording.segments.len(),
        recording.sample_rate_hz,
        samples as f64 / fs,
        meta("csv_longest_step_s"),
        meta("csv_steps_over_two_periods"),
        meta("csv_time_in_long_steps_s"),
        mcap.display()
    );
    Ok(())
}
