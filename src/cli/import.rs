//! `gyrodrift import csv`: measured data (CSV, plain or gzip) → an MCAP recording that `fit`,
//! `report` and `diagnose` read.
//!
//! The output is either one `.mcap` file or a campaign folder: `<out>/recordings/<unit>_<stem>.mcap`
//! and `<out>/import.json` (the source, the options and what was read). The CSV is read and
//! validated completely before anything is written (errors name the file, the row and the column);
//! the MCAP file is written to a temporary sibling and renamed, the manifest with `write_atomic`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_recording::{
    read_csv, write_recording, CsvAuxColumn, CsvColumns, CsvOptions, CsvTiming, RateUnit,
    SeriesKind, TimeUnit, RECORDINGS_DIR,
};

use drift_report::write_atomic;

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
    Campaign(CampaignArgs),
    /// PX4 ULog files (`.ulg`): a file, or a folder of them as one series.
    Ulog(super::import_ulog::UlogArgs),
}

/// Options of `gyrodrift import csv`.
#[derive(Debug, clap::Args)]
pub struct CsvArgs {
    /// The CSV file.
    pub file: PathBuf,
    /// Output: a `.mcap` file, or a campaign folder (gets `recordings/<unit>_<stem>.mcap` and
    /// `import.json`).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
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
}

/// How the rows of a CSV file are read: column mapping, units and timing (shared by `import csv`
/// and `import campaign`).
#[derive(Debug, clap::Args)]
pub struct ReadingArgs {
    /// Time column.
    #[arg(long, default_value = "t_s")]
    pub time_column: String,
    /// Unit of the time column: `s` or `ms`.
    #[arg(long, default_value = "s")]
    pub time_unit: String,
    /// Rate columns X, Y, Z.
    #[arg(long, value_delimiter = ',', num_args = 1.., default_value = "gx_dps,gy_dps,gz_dps")]
    pub rate_columns: Vec<String>,
    /// Unit of the rate columns: `deg/s` or `rad/s`.
    #[arg(long, default_value = "deg/s")]
    pub rate_unit: String,
    /// Temperature column(s), °C: one (a single die sensor for all axes) or three (X, Y, Z).
    #[arg(long, value_delimiter = ',', num_args = 1.., default_value = "temp_c")]
    pub temperature_columns: Vec<String>,
    /// Accelerometer columns X, Y, Z in g → the recording's `/aux/accel` channel (100 Hz).
    #[arg(long, value_delimiter = ',', num_args = 1..)]
    pub accel_columns: Option<Vec<String>>,
    /// Supply-voltage column in V → the recording's `/aux/supply_voltage` channel (100 Hz).
    #[arg(long)]
    pub supply_column: Option<String>,
    /// Any other column → a named auxiliary channel `/aux/<name>` (100 Hz), repeatable:
    /// `name=column` or `name=column:unit` (the unit follows the last `:`). Names: ASCII letters,
    /// digits, `_`, `.`, `-`, starting with a letter or digit.
    #[arg(long = "aux", value_name = "NAME=COLUMN[:UNIT]")]
    pub aux: Vec<String>,
    /// Sample rate of the recording's fixed grid, Hz (must divide 10⁹).
    #[arg(long, default_value_t = 1000)]
    pub rate_hz: u32,
    /// `strict`: every row is the next sample on the grid (a late row is a gap: an error);
    /// `resample`: host timestamps, interpolated linearly onto the grid.
    #[arg(long, default_value = "strict")]
    pub timing: String,
    /// With `--timing resample`: the longest step between rows that is interpolated across, s;
    /// a longer one is an error naming its row.
    #[arg(long, default_value_t = 0.5)]
    pub max_gap: f64,
    /// Read an empty or NaN temperature cell as a sensor dropout instead of an error.
    #[arg(long)]
    pub temperature_dropouts: bool,
    /// Largest plausible |rate|, °/s: a row beyond it is an error naming the row and column.
    #[arg(long, default_value_t = drift_recording::MAX_PLAUSIBLE_RATE_DPS)]
    pub max_rate: f64,
}

/// Options of `gyrodrift import campaign`.
#[derive(Debug, clap::Args)]
pub struct CampaignArgs {
    /// The activation sheet (CSV: `file`, `unit`, `set_point_celsius`, `series`, `repeat`,
    /// `activation`, `off_before_s`, `series_kind`, `switch_on_s`; optional `interval_min`,
    /// `switch_on_ambient_celsius`). Its `file` cells are relative to its folder.
    pub sheet: PathBuf,
    /// Output: a new campaign folder (`recordings/<unit>_sp<set point>C_<kind>.mcap`,
    /// `import.json`); it must not exist or be empty.
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Column mapping, units and timing of every activation file.
    #[command(flatten)]
    pub reading: ReadingArgs,
}

fn three(option: &'static str, names: &[String]) -> anyhow::Result<[String; 3]> {
    match names {
        [x, y, z] => Ok([x.clone(), y.clone(), z.clone()]),
        _ => anyhow::bail!(
            "option `--{option}`: expected 3 comma-separated columns (X,Y,Z), got {}: {}",
            names.len(),
            names.join(",")
        ),
    }
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

impl ReadingArgs {
    /// The reader's options for these columns, units and timing (unit id, set point, series kind
    /// and activation column at their defaults), with each bad value named by its option.
    pub fn options(&self) -> anyhow::Result<CsvOptions> {
        let temperature = match self.temperature_columns.as_slice() {
            [one] => [one.clone(), one.clone(), one.clone()],
            names => three("temperature-columns", names)
                .context("give one temperature column (a single sensor) or three (one per axis)")?,
        };
        let timing = match self.timing.as_str() {
            "strict" => CsvTiming::Strict,
            "resample" => CsvTiming::Resample {
                max_gap_s: self.max_gap,
            },
            other => {
                anyhow::bail!("option `--timing`: expected `strict` or `resample`, got `{other}`")
            }
        };
        Ok(CsvOptions {
            columns: CsvColumns {
                time_s: self.time_column.clone(),
                rate_dps: three("rate-columns", &self.rate_columns)?,
                temperature_celsius: temperature,
                segment: None,
                accel_g: self
                    .accel_columns
                    .as_deref()
                    .map(|names| three("accel-columns", names))
                    .transpose()?,
                supply_voltage: self.supply_column.clone(),
                aux: self
                    .aux
                    .iter()
                    .map(|text| {
                        CsvAuxColumn::parse(text)
                            .map_err(|e| anyhow::anyhow!("option `--aux`: {e}"))
                    })
                    .collect::<anyhow::Result<_>>()?,
            },
            sample_rate_hz: self.rate_hz,
            timing,
            temperature_dropouts: self.temperature_dropouts,
            rate_unit: RateUnit::parse(&self.rate_unit).ok_or_else(|| {
                anyhow::anyhow!(
                    "option `--rate-unit`: expected `deg/s` or `rad/s`, got `{}`",
                    self.rate_unit
                )
            })?,
            time_unit: TimeUnit::parse(&self.time_unit).ok_or_else(|| {
                anyhow::anyhow!(
                    "option `--time-unit`: expected `s` or `ms`, got `{}`",
                    self.time_unit
                )
            })?,
            max_rate_dps: self.max_rate,
            ..CsvOptions::default()
        })
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
    }
}

fn run_csv(args: &CsvArgs) -> anyhow::Result<()> {
    let options = args.options()?;
    // Read and validate everything first: an error leaves the output untouched.
    let recording = read_csv(&args.file, &options)?;
    let (mcap, manifest) = destination(&args.out, &args.unit_id, &args.file);
    let samples: usize = recording.segments.iter().map(|s| s.len()).sum();
    let fs = f64::from(recording.sample_rate_hz);
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
    let bytes = write_recording(&recording, &mcap)?;
    if let Some(path) = &manifest {
        write_atomic(path, manifest_bytes.as_bytes())?;
    }
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
