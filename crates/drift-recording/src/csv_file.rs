//! Measured data from CSV (plain or gzip): rows of time, three rates and three temperatures →
//! one [`Segment`] per activation, validated like the MCAP reader (errors name the file, the
//! column and the row).
//!
//! Column mapping ([`CsvColumns`], defaults in brackets): time in seconds [`t_s`], rates in °/s
//! [`gx_dps`, `gy_dps`, `gz_dps`], temperatures in °C per axis [`temp_c` for all three: a
//! single die sensor], and an optional activation column [`segment_id`]: consecutive rows with
//! the same value are one activation. Temperatures become raw readings at 200 raw/°C (the
//! recording format's scale), rounded. Optional auxiliary columns (accelerometer X, Y, Z in g,
//! supply voltage in V) go to the format's auxiliary channels, and any other column mapped in
//! [`CsvColumns::aux`] to a named channel of its own, all at the format's 100 Hz
//! ([`crate::AUX_RATE_HZ`]); columns not mapped are ignored. Rates may be given in rad/s and times
//! in ms ([`RateUnit`], [`TimeUnit`]). The defaults read the MPU6050 static recordings of
//! `sunsided/sensor-fusion` (`../shared/data/measured/`).
//!
//! Timing ([`CsvTiming`]): `Strict` takes every row as one sample of a fixed-rate stream: times
//! must sit on the grid, with no gap; `Resample` is for host-timestamped logs with jitter
//! (times strictly increasing, gaps up to a limit), linearly interpolated onto the fixed grid.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::aux::check_named_aux_channel;
use crate::csv_aux::CsvAuxColumn;
use crate::layout::AUX_RATE_HZ;
use crate::read::Recording;
use crate::segment::{
    AuxChannel, Segment, SegmentLabels, SeriesKind, RAW_PER_CELSIUS, TEMPERATURE_MISSING_RAW,
};

/// Which CSV column holds what (header names).
#[derive(Debug, Clone, PartialEq)]
pub struct CsvColumns {
    /// Time, seconds, 0 … 292 years (any origin: each activation starts at its first row).
    pub time_s: String,
    /// Angular rate X, Y, Z, °/s.
    pub rate_dps: [String; 3],
    /// Temperature for X, Y, Z, °C (the same column three times for a single sensor).
    pub temperature_celsius: [String; 3],
    /// Activation id: consecutive rows with the same value form one activation. `None`: the whole
    /// file is one activation.
    pub segment: Option<String>,
    /// Accelerometer X, Y, Z, g → the `/aux/accel` channel (`accel_x`, `accel_y`, `accel_z`).
    /// `None`: no accelerometer.
    pub accel_g: Option<[String; 3]>,
    /// Supply voltage, V → the `/aux/supply_voltage` channel. `None`: not recorded.
    pub supply_voltage: Option<String>,
    /// Any other columns, each → a named channel on `/aux/<channel>`.
    pub aux: Vec<CsvAuxColumn>,
}

impl Default for CsvColumns {
    fn default() -> Self {
        let s = |v: &str| v.to_owned();
        Self {
            time_s: s("t_s"),
            rate_dps: [s("gx_dps"), s("gy_dps"), s("gz_dps")],
            temperature_celsius: [s("temp_c"), s("temp_c"), s("temp_c")],
            segment: Some(s("segment_id")),
            accel_g: None,
            supply_voltage: None,
            aux: Vec::new(),
        }
    }
}

/// Unit of the rate columns (segments hold °/s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RateUnit {
    /// Degrees per second.
    #[default]
    DegPerSec,
    /// Radians per second (multiplied by 180/π).
    RadPerSec,
}

impl RateUnit {
    /// Parses `deg/s` (or `dps`) and `rad/s`.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "deg/s" | "dps" => Some(Self::DegPerSec),
            "rad/s" => Some(Self::RadPerSec),
            _ => None,
        }
    }

    /// Factor to °/s.
    pub fn to_dps(self) -> f64 {
        match self {
            Self::DegPerSec => 1.0,
            Self::RadPerSec => 180.0 / std::f64::consts::PI,
        }
    }
}

/// Unit of the time column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeUnit {
    /// Seconds.
    #[default]
    Seconds,
    /// Milliseconds (divided by 1000).
    Milliseconds,
}

impl TimeUnit {
    /// Parses `s` and `ms`.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "s" => Some(Self::Seconds),
            "ms" => Some(Self::Milliseconds),
            _ => None,
        }
    }

    /// Factor to seconds.
    pub fn to_seconds(self) -> f64 {
        match self {
            Self::Seconds => 1.0,
            Self::Milliseconds => 1e-3,
        }
    }
}

/// How row times map onto the fixed sample grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CsvTiming {
    /// Every row is the next sample: `(t − t_first) · rate` must be within 0.25 of the row's index
    /// in its activation. A late row is a gap, an early or repeated one an error.
    Strict,
    /// Host timestamps: times strictly increasing, no step longer than `max_gap_s`; the values
    /// are interpolated linearly onto the grid `k / rate` from the activation's first row.
    Resample {
        /// Longest accepted step between consecutive rows, s.
        max_gap_s: f64,
    },
}

/// How to read a CSV file.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvOptions {
    /// Column mapping.
    pub columns: CsvColumns,
    /// Sample rate of the segments, Hz (must divide 10⁹, like the recording format's).
    pub sample_rate_hz: u32,
    /// Timing policy.
    pub timing: CsvTiming,
    /// Unit id of every activation.
    pub unit_id: String,
    /// Chamber set point of every activation, °C; `None`: each activation's first temperature
    /// (mean over the axes), i.e. the ambient at switch-on.
    pub set_point_celsius: Option<f64>,
    /// Series kind of every activation.
    pub series_kind: SeriesKind,
    /// Accept an empty or NaN temperature cell as a sensor dropout
    /// ([`TEMPERATURE_MISSING_RAW`]); otherwise it is an error. Rates never accept one.
    pub temperature_dropouts: bool,
    /// Unit of the rate columns.
    pub rate_unit: RateUnit,
    /// Unit of the time column.
    pub time_unit: TimeUnit,
    /// Largest plausible |rate|, °/s: a row beyond it is an error naming the row and column (a
    /// wrong unit, a corrupt cell), not a bias to fit. Default [`MAX_PLAUSIBLE_RATE_DPS`].
    pub max_rate_dps: f64,
}

/// Default [`CsvOptions::max_rate_dps`], °/s: 2.5× the widest full-scale range of MEMS gyroscopes
/// (±4000 °/s); anything beyond is not a gyroscope's rate.
pub const MAX_PLAUSIBLE_RATE_DPS: f64 = 10_000.0;

impl Default for CsvOptions {
    fn default() -> Self {
        Self {
            columns: CsvColumns::default(),
            sample_rate_hz: 1000,
            timing: CsvTiming::Strict,
            unit_id: "csv".into(),
            set_point_celsius: None,
            series_kind: SeriesKind::Protocol,
            temperature_dropouts: false,
            rate_unit: RateUnit::DegPerSec,
            time_unit: TimeUnit::Seconds,
            max_rate_dps: MAX_PLAUSIBLE_RATE_DPS,
        }
    }
}

impl CsvOptions {
    /// The MPU6050 static recordings (`mpu6050_static.csv.gz`): 100 Hz host timestamps with jitter
    /// and pauses up to 0.5 s, one die temperature.
    pub fn mpu6050_static() -> Self {
        Self {
            sample_rate_hz: 100,
            timing: CsvTiming::Resample { max_gap_s: 0.5 },
            unit_id: "MPU6050".into(),
            ..Self::default()
        }
    }
}

/// A CSV file could not be read or failed validation. Every variant names the file; value
/// errors name the column and the row.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// File-system or decompression error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A gzip-compressed file that does not decompress.
    #[error("{path}: gzip: {reason} after {decompressed} decompressed bytes: the compressed file is corrupt or cut short")]
    Gzip {
        /// The file.
        path: PathBuf,
        /// The decompressor's error.
        reason: String,
        /// Bytes decompressed before it.
        decompressed: usize,
    },
    /// Gzip-compressed data in a file whose name does not say so (no `.gz` ending).
    #[error("{path}: the file holds gzip-compressed data (it starts with bytes 1f 8b), but its name does not end in `.gz`: name it `{}.gz`, or decompress it", path.display())]
    GzipContent {
        /// The file.
        path: PathBuf,
    },
    /// The options cannot be used.
    #[error("{path}: option `{field}`: {reason}")]
    Options {
        /// The file.
        path: PathBuf,
        /// The option.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// A mapped column is not in the header.
    #[error("{path}: missing column `{column}` (the header has: {header})")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column asked for.
        column: String,
        /// The header's columns, comma-separated.
        header: String,
    },
    /// A row is malformed or inconsistent with its neighbours.
    #[error("{path}: row {row} (line {line}){}: {reason}", column.as_ref().map(|c| format!(", column `{c}`")).unwrap_or_default())]
    Row {
        /// The file.
        path: PathBuf,
        /// Data row, from 1 (the header is not counted).
        row: u64,
        /// Line in the file, from 1 (the header is line 1).
        line: u64,
        /// The column, when one value is at fault.
        column: Option<String>,
        /// What is wrong: expected vs found.
        reason: String,
    },
    /// The file has a header but no data row.
    #[error("{path}: no data rows")]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// Reads a CSV file (gzip-compressed if its name ends in `.gz`) into a [`Recording`] whose
/// metadata says where it came from; [`crate::write_recording`] then converts it to MCAP.
pub fn read_csv(path: &Path, options: &CsvOptions) -> Result<Recording, CsvError> {
    let io = |source| CsvError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let gz = path.extension().is_some_and(|e| e == "gz");
    if gz {
        // Decompressed whole first, so a corrupt or cut-short gzip stream is reported as such,
        // not as whatever CSV error the garbage before the gzip check happens to make.
        let mut text = Vec::new();
        flate2::read::MultiGzDecoder::new(std::io::BufReader::new(file))
            .read_to_end(&mut text)
            .map_err(|e| CsvError::Gzip {
                path: path.to_path_buf(),
                reason: e.to_string(),
                decompressed: text.len(),
            })?;
        return read_csv_from(path, text.as_slice(), options);
    }
    let mut reader = std::io::BufReader::new(file);
    if std::io::BufRead::fill_buf(&mut reader)
        .map_err(io)?
        .starts_with(&GZIP_MAGIC)
    {
        return Err(CsvError::GzipContent {
            path: path.to_path_buf(),
        });
    }
    read_csv_from(path, reader, options)
}

/// The first bytes of a gzip stream (RFC 1952).
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Reads CSV text held in memory (not compressed); `name` stands for the file in errors. The same
/// checks as [`read_csv`]; fuzzing drives it directly.
pub fn read_csv_bytes(
    name: &Path,
    bytes: &[u8],
    options: &CsvOptions,
) -> Result<Recording, CsvError> {
    read_csv_from(name, bytes, options)
}

/// One activation's rows as read, before they are put on the grid.
#[derive(Default)]
struct Rows {
    id: String,
    time_s: Vec<f64>,
    rate: [Vec<f64>; 3],
    celsius: [Vec<f64>; 3],
    /// Auxiliary columns, in the order of [`Columns::aux`].
    aux: Vec<Vec<f64>>,
    /// (row, line) of every row, for errors found after reading.
    at: Vec<(u64, u64)>,
}

struct Columns {
    time: usize,
    rate: [usize; 3],
    temperature: [usize; 3],
    segment: Option<usize>,
    /// Auxiliary columns: (index, column name, channel name, unit).
    aux: Vec<(usize, String, String, String)>,
}

fn read_csv_from<R: Read>(
    path: &Path,
    input: R,
    options: &CsvOptions,
) -> Result<Recording, CsvError> {
    let fs = options.sample_rate_hz;
    if fs == 0 || 1_000_000_000 % fs != 0 {
        return Err(CsvError::Options {
            path: path.to_path_buf(),
            field: "sample_rate_hz",
            reason: format!("must divide 10⁹, got {fs}"),
        });
    }
    if let CsvTiming::Resample { max_gap_s } = options.timing {
        if !(max_gap_s.is_finite() && max_gap_s > 0.0) {
            return Err(CsvError::Options {
                path: path.to_path_buf(),
                field: "timing.max_gap_s",
                reason: format!("must be > 0 s, got {max_gap_s}"),
            });
        }
    }
    if let Some(set_point) = options.set_point_celsius {
        // The reader refuses a recording whose set point is not a finite number: refuse it here,
        // before anything is written.
        if !set_point.is_finite() {
            return Err(CsvError::Options {
                path: path.to_path_buf(),
                field: "set_point_celsius",
                reason: format!("must be a finite number of °C, got {set_point}"),
            });
        }
    }
    if !(options.max_rate_dps.is_finite() && options.max_rate_dps > 0.0) {
        return Err(CsvError::Options {
            path: path.to_path_buf(),
            field: "max_rate_dps",
            reason: format!("must be > 0 °/s, got {}", options.max_rate_dps),
        });
    }
    let mut reader = csv::ReaderBuilder::new().flexible(false).from_reader(input);
    let header = reader
        .headers()
        .map_err(|e| row_error(path, &e, 0, 1))?
        .clone();
    let find = |name: &str| {
        header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or_else(|| CsvError::MissingColumn {
                path: path.to_path_buf(),
                column: name.to_owned(),
                header: header.iter().collect::<Vec<_>>().join(","),
            })
    };
    let c = &options.columns;
    check_named_columns(path, &c.aux)?;
    let columns = Columns {
        time: find(&c.time_s)?,
        rate: [
            find(&c.rate_dps[0])?,
            find(&c.rate_dps[1])?,
            find(&c.rate_dps[2])?,
        ],
        temperature: [
            find(&c.temperature_celsius[0])?,
            find(&c.temperature_celsius[1])?,
            find(&c.temperature_celsius[2])?,
        ],
        segment: c.segment.as_deref().map(find).transpose()?,
        aux: {
            let mut aux = Vec::new();
            if let Some(names) = &c.accel_g {
                for (name, channel) in names.iter().zip(["accel_x", "accel_y", "accel_z"]) {
                    aux.push((find(name)?, name.clone(), channel.into(), "g".into()));
                }
            }
            if let Some(name) = &c.supply_voltage {
                aux.push((
                    find(name)?,
                    name.clone(),
                    "supply_voltage".into(),
                    "V".into(),
                ));
            }
            for named in &c.aux {
                let index = find(&named.column)?;
                aux.push((
                    index,
                    named.column.clone(),
                    named.channel.clone(),
                    named.unit.clone(),
                ));
            }
            aux
        },
    };
    if !columns.aux.is_empty() && fs % AUX_RATE_HZ != 0 {
        return Err(CsvError::Options {
            path: path.to_path_buf(),
            field: "sample_rate_hz",
            reason: format!(
                "auxiliary columns are recorded at {AUX_RATE_HZ} Hz, which needs a sample rate that is a multiple of it, got {fs} Hz"
            ),
        });
    }
    let mut done: Vec<Rows> = Vec::new();
    let mut current: Option<Rows> = None;
    let mut record = csv::StringRecord::new();
    let mut row = 0u64;
    loop {
        let line = reader.position().line();
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(row_error(path, &e, row + 1, line)),
        }
        row += 1;
        let line = record.position().map_or(line, csv::Position::line);
        let bad = |column: &str, reason: String| CsvError::Row {
            path: path.to_path_buf(),
            row,
            line,
            column: Some(column.to_owned()),
            reason,
        };
        let id = columns
            .segment
            .map(|i| record.get(i).unwrap_or_default().trim().to_owned())
            .unwrap_or_default();
        if current.as_ref().is_none_or(|r| r.id != id) {
            if let Some(finished) = current.take() {
                if done.iter().any(|d| d.id == id) || finished.id == id {
                    let column = c.segment.as_deref().unwrap_or_default();
                    return Err(bad(
                        column,
                        format!("activation `{id}` resumes after activation `{}`: rows of one activation must be consecutive", finished.id),
                    ));
                }
                done.push(finished);
            }
            current = Some(Rows {
                id,
                aux: vec![Vec::new(); columns.aux.len()],
                ..Rows::default()
            });
        }
        let rows = current
            .as_mut()
            .ok_or_else(|| bad(&c.time_s, "internal: no activation".into()))?;
        let number = |index: usize, name: &str| -> Result<f64, CsvError> {
            let text = record.get(index).unwrap_or_default().trim();
            text.parse::<f64>()
                .map_err(|_| bad(name, format!("`{text}` is not a number")))
        };
        let time = number(columns.time, &c.time_s)? * options.time_unit.to_seconds();
        if !time.is_finite() {
            return Err(bad(&c.time_s, format!("time is {time}")));
        }
        if let Some(&previous) = rows.time_s.last() {
            if time == previous {
                return Err(bad(
                    &c.time_s,
                    format!("duplicate time {time} s (the previous row has the same)"),
                ));
            }
            if time < previous {
                return Err(bad(
                    &c.time_s,
                    format!("time {time} s goes back (previous row {previous} s)"),
                ));
            }
        }
        for axis in 0..3 {
            let rate = number(columns.rate[axis], &c.rate_dps[axis])? * options.rate_unit.to_dps();
            if !rate.is_finite() {
                return Err(bad(&c.rate_dps[axis], format!("non-finite rate {rate}")));
            }
            // Segments hold f32: a finite f64 beyond f32's range would become ±∞ there.
            if !(rate as f32).is_finite() {
                return Err(bad(
                    &c.rate_dps[axis],
                    format!("rate {rate:.3e} °/s is beyond the f32 range of a segment"),
                ));
            }
            if rate.abs() > options.max_rate_dps {
                return Err(bad(
                    &c.rate_dps[axis],
                    format!(
                        "rate {rate:.3e} °/s is beyond the plausible {} °/s (a wrong unit or a \
                         corrupt cell? raise the limit if the gyroscope really measures this)",
                        options.max_rate_dps
                    ),
                ));
            }
            rows.rate[axis].push(rate);
            let name = &c.temperature_celsius[axis];
            let text = record
                .get(columns.temperature[axis])
                .unwrap_or_default()
                .trim();
            let celsius = if text.is_empty() {
                f64::NAN
            } else {
                number(columns.temperature[axis], name)?
            };
            if celsius.is_nan() && !options.temperature_dropouts {
                return Err(bad(name, format!("missing temperature `{text}` (set temperature_dropouts to read it as a sensor dropout)")));
            }
            if celsius.is_infinite() || (celsius.is_finite() && !raw_in_range(celsius)) {
                return Err(bad(
                    name,
                    format!("temperature {celsius} °C is outside the raw range (±163.8 °C)"),
                ));
            }
            rows.celsius[axis].push(celsius);
        }
        for (k, (index, name, _, unit)) in columns.aux.iter().enumerate() {
            let value = number(*index, name)?;
            if !(value.is_finite() && (value as f32).is_finite()) {
                return Err(bad(
                    name,
                    format!("auxiliary value {value} {unit} is not a finite f32"),
                ));
            }
            rows.aux[k].push(value);
        }
        rows.time_s.push(time);
        rows.at.push((row, line));
    }
    done.extend(current);
    if done.is_empty() {
        return Err(CsvError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut segments = done
        .iter()
        .enumerate()
        .map(|(k, rows)| {
            let mut segment = to_segment(path, rows, k, options)?;
            add_aux(&mut segment, rows, &columns, options);
            Ok(segment)
        })
        .collect::<Result<Vec<_>, CsvError>>()?;
    let timing = TimingStats::of(&done, f64::from(fs));
    // Activations whose clock restarts (each from t = 0, as in the MPU6050 file) are laid out one
    // second apart, so the recording's log times increase and it can be written as MCAP.
    let period_ns = 1_000_000_000 / u64::from(fs);
    let mut end_ns = 0u64;
    for (k, s) in segments.iter_mut().enumerate() {
        // `<=`: a switch-on at the previous switch-off's time would repeat a power-event timestamp.
        if k > 0 && s.power_on_ns <= end_ns {
            s.power_on_ns = end_ns.saturating_add(1_000_000_000);
        }
        end_ns = s.power_on_ns.saturating_add(s.len() as u64 * period_ns);
    }
    let metadata = [
        ("format_version", crate::schema::FORMAT_VERSION.to_owned()),
        ("unit_id", options.unit_id.clone()),
        ("sample_rate_hz", fs.to_string()),
        ("series_kind", options.series_kind.as_str().to_owned()),
        ("temperature_raw_per_celsius", format!("{RAW_PER_CELSIUS}")),
        ("source", format!("csv: {}", path.display())),
        ("csv_rows", timing.rows.to_string()),
        (
            "csv_longest_step_s",
            format!("{:.6}", timing.longest_step_s),
        ),
        ("csv_steps_over_two_periods", timing.long_steps.to_string()),
        (
            "csv_time_in_long_steps_s",
            format!("{:.3}", timing.long_steps_s),
        ),
        (
            "csv_smallest_temperature_step_celsius",
            format!("{:.6}", timing.temperature_step_celsius),
        ),
        (
            "csv_timing",
            match options.timing {
                CsvTiming::Strict => "strict".to_owned(),
                CsvTiming::Resample { max_gap_s } => {
                    format!("resampled linearly onto {fs} Hz, steps up to {max_gap_s} s")
                }
            },
        ),
    ]
    .into_iter()
    .chain(
        options
            .set_point_celsius
            .map(|s| ("set_point_celsius", format!("{s}"))),
    )
    .map(|(k, v)| (k.to_owned(), v))
    .collect();
    Ok(Recording {
        path: path.to_path_buf(),
        metadata,
        unit_id: options.unit_id.clone(),
        sample_rate_hz: fs,
        segments,
    })
}

/// How regular the rows' times were (what resampling bridged), over all activations.
struct TimingStats {
    rows: usize,
    longest_step_s: f64,
    /// Steps between consecutive rows longer than two sample periods.
    long_steps: usize,
    /// Time covered by those steps, s.
    long_steps_s: f64,
    /// Smallest non-zero change of the X temperature between consecutive rows (the sensor's
    /// step as logged), °C; infinite if it never changes.
    temperature_step_celsius: f64,
}

impl TimingStats {
    fn of(activations: &[Rows], fs: f64) -> Self {
        let mut stats = Self {
            rows: 0,
            longest_step_s: 0.0,
            long_steps: 0,
            long_steps_s: 0.0,
            temperature_step_celsius: f64::INFINITY,
        };
        for rows in activations {
            stats.rows += rows.time_s.len();
            for w in rows.time_s.windows(2) {
                let step = w[1] - w[0];
                stats.longest_step_s = stats.longest_step_s.max(step);
                if step > 2.0 / fs {
                    stats.long_steps += 1;
                    stats.long_steps_s += step;
                }
            }
            for w in rows.celsius[0].windows(2) {
                let change = (w[1] - w[0]).abs();
                if change > 0.0 {
                    stats.temperature_step_celsius = stats.temperature_step_celsius.min(change);
                }
            }
        }
        stats
    }
}

/// Linear interpolation of `values` (at `times`, strictly increasing) at `t`, held at the ends;
/// `j` is the search position, advanced monotonically for increasing `t`.
fn interpolate(times: &[f64], values: &[f64], t: f64, j: &mut usize) -> f64 {
    while *j + 2 < times.len() && times[*j + 1] <= t {
        *j += 1;
    }
    let a = values[*j];
    let (Some(&tb), Some(&b)) = (times.get(*j + 1), values.get(*j + 1)) else {
        return a;
    };
    let ta = times[*j];
    let w = if tb > ta {
        ((t - ta) / (tb - ta)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    a + (b - a) * w
}

/// Puts the auxiliary columns on the format's fixed auxiliary grid (sample `j` at `j / 100` s
/// after switch-on, as many as the activation's gyro samples cover): every `fs / 100`-th row for
/// `Strict` timing, interpolated like the rates for `Resample`.
fn add_aux(segment: &mut Segment, rows: &Rows, columns: &Columns, options: &CsvOptions) {
    let every = (options.sample_rate_hz / AUX_RATE_HZ).max(1) as usize;
    let count = segment.len().div_ceil(every);
    let t0 = rows.time_s.first().copied().unwrap_or_default();
    for (k, (_, _, channel, unit)) in columns.aux.iter().enumerate() {
        let source = &rows.aux[k];
        let values: Vec<f32> = match options.timing {
            CsvTiming::Strict => source.iter().step_by(every).map(|&v| v as f32).collect(),
            CsvTiming::Resample { .. } => {
                let mut j = 0;
                (0..count)
                    .map(|i| {
                        let t = t0 + i as f64 / f64::from(AUX_RATE_HZ);
                        interpolate(&rows.time_s, source, t, &mut j) as f32
                    })
                    .collect()
            }
        };
        segment.aux.insert(
            channel.clone(),
            AuxChannel {
                unit: unit.clone(),
                sample_rate_hz: AUX_RATE_HZ,
                values,
            },
        );
    }
}

/// The named channels must be ones the recording can hold, each once: checked before any row is
/// read, so a bad name is not found after minutes of a large file.
fn check_named_columns(path: &Path, named: &[CsvAuxColumn]) -> Result<(), CsvError> {
    let error = |reason: String| CsvError::Options {
        path: path.to_path_buf(),
        field: "columns.aux",
        reason,
    };
    for (k, aux) in named.iter().enumerate() {
        check_named_aux_channel(&aux.channel).map_err(error)?;
        if named[..k].iter().any(|a| a.channel == aux.channel) {
            return Err(error(format!(
                "auxiliary channel `{}` is mapped twice",
                aux.channel
            )));
        }
    }
    Ok(())
}

fn row_error(path: &Path, e: &csv::Error, row: u64, line: u64) -> CsvError {
    let (line, reason) = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } => (
            pos.as_ref().map_or(line, csv::Position::line),
            format!("{len} fields, the header has {expected_len}"),
        ),
        csv::ErrorKind::Io(io) => (line, format!("read error: {io}")),
        _ => (line, e.to_string()),
    };
    CsvError::Row {
        path: path.to_path_buf(),
        row,
        line,
        column: None,
        reason,
    }
}

/// Raw readings are `int16` at 200 raw/°C, and −32768 is the dropout marker.
fn raw_in_range(celsius: f64) -> bool {
    let raw = (celsius * RAW_PER_CELSIUS).round();
    raw > f64::from(TEMPERATURE_MISSING_RAW) && raw <= f64::from(i16::MAX)
}

fn to_raw(celsius: f64) -> i16 {
    if celsius.is_finite() {
        // In range: checked per row (interpolation stays between two checked values).
        (celsius * RAW_PER_CELSIUS).round() as i16
    } else {
        TEMPERATURE_MISSING_RAW
    }
}

fn to_segment(
    path: &Path,
    rows: &Rows,
    k: usize,
    options: &CsvOptions,
) -> Result<Segment, CsvError> {
    let fs = f64::from(options.sample_rate_hz);
    let t0 = rows.time_s.first().copied().unwrap_or_default();
    let at = |i: usize| rows.at.get(i).copied().unwrap_or_default();
    let timing_error = |i: usize, reason: String| {
        let (row, line) = at(i);
        CsvError::Row {
            path: path.to_path_buf(),
            row,
            line,
            column: Some(options.columns.time_s.clone()),
            reason,
        }
    };
    let mut rate: [Vec<f32>; 3] = Default::default();
    let mut raw: [Vec<i16>; 3] = Default::default();
    match options.timing {
        CsvTiming::Strict => {
            for (i, &t) in rows.time_s.iter().enumerate() {
                let position = (t - t0) * fs;
                let index = position.round();
                if (position - i as f64).abs() > 0.25 {
                    let what = if index > i as f64 {
                        "gap"
                    } else {
                        "early sample"
                    };
                    return Err(timing_error(
                        i,
                        format!(
                            "{what}: time {t} s is sample {position:.2} of the activation at {} Hz, expected sample {i} (host timestamps with jitter or pauses: read them with resampled timing: on the command line `--timing resample --rate-hz <the logging rate>`, in Python `max_gap_s=`)",
                            options.sample_rate_hz
                        ),
                    ));
                }
                for axis in 0..3 {
                    rate[axis].push(rows.rate[axis][i] as f32);
                    raw[axis].push(to_raw(rows.celsius[axis][i]));
                }
            }
        }
        CsvTiming::Resample { max_gap_s } => {
            if let Some(i) = rows.time_s.windows(2).position(|w| w[1] - w[0] > max_gap_s) {
                return Err(timing_error(
                    i + 1,
                    format!(
                        "gap: {:.3} s since the previous row (at most {max_gap_s} s)",
                        rows.time_s[i + 1] - rows.time_s[i]
                    ),
                ));
            }
            let last = rows.time_s.last().copied().unwrap_or(t0);
            let n = ((last - t0) * fs + 1e-9).floor() as usize + 1;
            if n > u32::MAX as usize / 2 {
                return Err(timing_error(
                    rows.time_s.len() - 1,
                    format!("activation of {} s is too long", last - t0),
                ));
            }
            let mut j = 0;
            for s in 0..n {
                let t = t0 + s as f64 / fs;
                while j + 2 < rows.time_s.len() && rows.time_s[j + 1] <= t {
                    j += 1;
                }
                let ta = rows.time_s[j];
                let tb = rows.time_s.get(j + 1).copied().unwrap_or(ta);
                let w = if tb > ta {
                    ((t - ta) / (tb - ta)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let lerp = |v: &[f64]| {
                    let a = v[j];
                    let b = v.get(j + 1).copied().unwrap_or(a);
                    if w == 0.0 {
                        a
                    } else if w == 1.0 {
                        b
                    } else {
                        a + (b - a) * w
                    }
                };
                for axis in 0..3 {
                    rate[axis].push(lerp(&rows.rate[axis]) as f32);
                    raw[axis].push(to_raw(lerp(&rows.celsius[axis])));
                }
            }
        }
    }
    let n = rate[0].len();
    let first: Vec<f64> = (0..3)
        .map(|a| rows.celsius[a][0])
        .filter(|c| c.is_finite())
        .collect();
    let set_point = match options.set_point_celsius {
        Some(s) => s,
        None if first.is_empty() => {
            return Err(timing_error(
                0,
                "no temperature in the activation's first row to take the set point from \
                 (give set_point_celsius)"
                    .into(),
            ))
        }
        None => first.iter().sum::<f64>() / first.len() as f64,
    };
    // The recording clock is u64 ns (584 years): a time beyond it is a bad row, not a wrap.
    let end_s = t0 + n as f64 / fs;
    if !(t0 >= 0.0 && end_s * 1e9 < u64::MAX as f64 / 2.0) {
        return Err(timing_error(
            0,
            format!("time {t0} s is outside the recording clock (0 … 292 years in ns)"),
        ));
    }
    let labels = SegmentLabels {
        unit_id: options.unit_id.clone(),
        set_point_celsius: set_point,
        session_set_point_celsius: options.set_point_celsius,
        series_kind: options.series_kind,
        series: u32::try_from(k + 1).unwrap_or(u32::MAX),
        repeat: 1,
        activation: 1,
        interval_min: None,
        off_before_s: None,
    };
    Ok(Segment {
        labels,
        sample_rate_hz: options.sample_rate_hz,
        power_on_ns: (t0 * 1e9).max(0.0) as u64,
        since_power_on: (0..n as u32).collect(),
        rate_dps: rate,
        temperature_raw: raw,
        temperature_scale: crate::TemperatureScale::default(),
        aux: Default::default(),
    })
}
