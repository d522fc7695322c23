//! How the rows of a CSV file are read (column mapping, units, timing): the options `import csv`
//! and `import campaign` share.

use anyhow::Context;
use drift_recording::{CsvAuxColumn, CsvColumns, CsvOptions, CsvTiming, RateUnit, TimeUnit};

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
