//! A bench campaign from files: one CSV file (plain or gzip) per activation and an activation
//! sheet that labels them → [`Recording`]s, one per unit × chamber set point × series kind, as
//! the simulator lays out a campaign.
//!
//! The sheet is a CSV file with a header row and one row per activation. Columns (any order;
//! others are ignored):
//!
//! | column | meaning | empty cell |
//! |---|---|---|
//! | `file` | the activation's file (CSV, or a log the caller reads: a ROS 2 bag file or folder, a PX4 ULog), relative to the sheet's folder | error |
//! | `unit` | unit id | error |
//! | `set_point_celsius` | chamber set point of the session, °C | error |
//! | `series` | series number (from 1) | error |
//! | `repeat` | repeat of the interval (from 1) | error |
//! | `activation` | activation number within the series (from 1) | error |
//! | `off_before_s` | off-time before this switch-on, s | unknown |
//! | `series_kind` | `protocol` or `field` | error |
//! | `switch_on_s` | switch-on time on the bench clock, s (≥ 0) | laid out after the previous activation |
//! | `interval_min` (optional) | the protocol's off-time between activations, min | none (field sessions) |
//! | `switch_on_ambient_celsius` (optional) | chamber temperature at switch-on, °C, when it differs from the set point (a ramping field session) | the set point |
//!
//! Each activation gets the format's `chamber_set_point` channel, constant at its switch-on
//! ambient (when the sample rate is a multiple of the channel's 100 Hz). Each activation file is
//! read with [`crate::read_csv`] and the caller's column mapping, units
//! and timing, as one activation (no activation column). Every error names the sheet or the
//! activation file, the row and the column.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::aux::fixed_aux_unit;
use crate::csv_file::{read_csv, CsvError, CsvOptions};
use crate::layout::AUX_RATE_HZ;
use crate::read::Recording;
use crate::segment::{AuxChannel, Segment, SeriesKind, RAW_PER_CELSIUS};
use crate::sheet_units;

/// The format's own auxiliary channel of the chamber's set point, °C.
const SET_POINT_CHANNEL: &str = "chamber_set_point";

/// The sheet's required columns, in the order the table above gives them.
pub const SHEET_COLUMNS: [&str; 9] = [
    "file",
    "unit",
    "set_point_celsius",
    "series",
    "repeat",
    "activation",
    "off_before_s",
    "series_kind",
    "switch_on_s",
];

/// A sheet or one of its activation files could not be read or is inconsistent.
#[derive(Debug, thiserror::Error)]
pub enum SheetError {
    /// The sheet could not be opened or parsed.
    #[error("{path}: {reason}")]
    Sheet {
        /// The sheet.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A required column is missing from the sheet's header.
    #[error("{path}: missing column `{column}` (the header has: {header})")]
    MissingColumn {
        /// The sheet.
        path: PathBuf,
        /// The column.
        column: String,
        /// The header's columns, comma-separated.
        header: String,
    },
    /// A sheet row is wrong.
    #[error("{path}: row {row} (line {line}), column `{column}`: {reason}")]
    Row {
        /// The sheet.
        path: PathBuf,
        /// Data row, from 1 (the header is not counted).
        row: u64,
        /// Line in the sheet, from 1.
        line: u64,
        /// The column at fault.
        column: String,
        /// What is wrong: expected vs found.
        reason: String,
    },
    /// An activation file failed to read: the sheet's row here, the file's row and column in the
    /// source error (shown after it by an error chain, `{:#}`).
    #[error("{sheet}: row {row} (line {line}), column `file`")]
    File {
        /// The sheet.
        sheet: PathBuf,
        /// The sheet's data row naming the file.
        row: u64,
        /// Its line.
        line: u64,
        /// The activation file's error.
        source: Box<CsvError>,
    },
    /// An activation log (a ROS 2 bag, a ULog) failed to read: the sheet's row here, the log's
    /// file, topic and message in the source error.
    #[error("{sheet}: row {row} (line {line}), column `file`")]
    Log {
        /// The sheet.
        sheet: PathBuf,
        /// The sheet's data row naming the log.
        row: u64,
        /// Its line.
        line: u64,
        /// The log reader's error.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The sheet has no data row.
    #[error("{path}: no activations (the sheet has a header but no data rows)")]
    Empty {
        /// The sheet.
        path: PathBuf,
    },
}

/// One row of the sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct SheetRow {
    /// The activation file, resolved against the sheet's folder.
    pub file: PathBuf,
    /// Unit id.
    pub unit: String,
    /// Chamber set point of the session, °C.
    pub set_point_celsius: f64,
    /// Chamber temperature at switch-on, °C (`None`: the set point).
    pub switch_on_ambient_celsius: Option<f64>,
    /// Series number.
    pub series: u32,
    /// Repeat.
    pub repeat: u32,
    /// Activation number within the series.
    pub activation: u32,
    /// Off-time before the switch-on, s (`None`: unknown).
    pub off_before_s: Option<f64>,
    /// The protocol's interval, min (`None`: not a protocol series).
    pub interval_min: Option<f64>,
    /// Series kind.
    pub series_kind: SeriesKind,
    /// Switch-on time on the bench clock, ns (`None`: not logged).
    pub switch_on_ns: Option<u64>,
    /// (row, line) in the sheet.
    pub at: (u64, u64),
}

/// Reads and checks the sheet (not the activation files).
pub fn read_sheet(path: &Path) -> Result<Vec<SheetRow>, SheetError> {
    let sheet_error = |reason: String| SheetError::Sheet {
        path: path.to_path_buf(),
        reason,
    };
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_path(path)
        .map_err(|e| sheet_error(e.to_string()))?;
    let header = reader
        .headers()
        .map_err(|e| sheet_error(e.to_string()))?
        .clone();
    let find = |name: &str| header.iter().position(|h| h.trim() == name);
    let mut index = BTreeMap::new();
    for name in SHEET_COLUMNS {
        let i = find(name).ok_or_else(|| SheetError::MissingColumn {
            path: path.to_path_buf(),
            column: name.to_owned(),
            header: header.iter().collect::<Vec<_>>().join(","),
        })?;
        index.insert(name, i);
    }
    let interval = find("interval_min");
    let ambient = find("switch_on_ambient_celsius");
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut rows = Vec::new();
    let mut seen_files = BTreeMap::new();
    let mut seen_labels = BTreeMap::new();
    let mut record = csv::StringRecord::new();
    let mut row = 0u64;
    loop {
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                let line = e.position().map_or(0, csv::Position::line);
                return Err(sheet_error(format!("row {} (line {line}): {e}", row + 1)));
            }
        }
        row += 1;
        let line = record.position().map_or(0, csv::Position::line);
        let bad = |column: &str, reason: String| SheetError::Row {
            path: path.to_path_buf(),
            row,
            line,
            column: column.to_owned(),
            reason,
        };
        let cell = |i: usize| record.get(i).unwrap_or_default().trim();
        let text = |name: &'static str| cell(index[name]);
        let required = |name: &'static str| {
            let t = text(name);
            if t.is_empty() {
                Err(bad(name, "empty cell".into()))
            } else {
                Ok(t)
            }
        };
        let number = |name: &'static str, t: &str| -> Result<f64, SheetError> {
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(bad(name, format!("`{t}` is not a finite number"))),
            }
        };
        let optional = |name: &'static str, i: Option<usize>| -> Result<Option<f64>, SheetError> {
            match i.map(cell).filter(|t| !t.is_empty()) {
                None => Ok(None),
                Some(t) => number(name, t).map(Some),
            }
        };
        let count = |name: &'static str| -> Result<u32, SheetError> {
            let t = required(name)?;
            match t.parse::<u32>() {
                Ok(v) if v >= 1 => Ok(v),
                _ => Err(bad(name, format!("expected a whole number ≥ 1, got `{t}`"))),
            }
        };
        let file_text = required("file")?;
        let file = folder.join(file_text);
        if !file.exists() {
            return Err(bad("file", format!("no such file `{}`", file.display())));
        }
        if let Some(first) = seen_files.insert(file.clone(), row) {
            return Err(bad(
                "file",
                format!("`{file_text}` is listed twice (first in row {first})"),
            ));
        }
        let unit = required("unit")?.to_owned();
        let set_point_celsius = number("set_point_celsius", required("set_point_celsius")?)?;
        let switch_on_ambient_celsius = optional("switch_on_ambient_celsius", ambient)?;
        for (name, celsius) in [
            ("set_point_celsius", Some(set_point_celsius)),
            ("switch_on_ambient_celsius", switch_on_ambient_celsius),
        ] {
            if celsius.is_some_and(|c| (c * RAW_PER_CELSIUS).abs() > f64::from(i16::MAX)) {
                return Err(bad(
                    name,
                    format!(
                        "{} °C is outside the sensor range (±163.8 °C)",
                        celsius.unwrap_or_default()
                    ),
                ));
            }
        }
        let series = count("series")?;
        let repeat = count("repeat")?;
        let activation = count("activation")?;
        let off_before_s = optional("off_before_s", Some(index["off_before_s"]))?;
        if off_before_s.is_some_and(|s| s < 0.0) {
            return Err(bad("off_before_s", "off-time must be ≥ 0 s".into()));
        }
        let interval_min = optional("interval_min", interval)?;
        if interval_min.is_some_and(|m| m <= 0.0) {
            return Err(bad("interval_min", "interval must be > 0 min".into()));
        }
        let kind_text = required("series_kind")?;
        let series_kind = SeriesKind::parse(kind_text).ok_or_else(|| {
            bad(
                "series_kind",
                format!("expected `protocol` or `field`, got `{kind_text}`"),
            )
        })?;
        let switch_on_ns = match optional("switch_on_s", Some(index["switch_on_s"]))? {
            None => None,
            Some(s) if (0.0..1.8e10).contains(&s) => Some((s * 1e9).round() as u64),
            Some(s) => {
                return Err(bad(
                    "switch_on_s",
                    format!("{s} s is outside the recording clock (0 … 570 years in ns)"),
                ))
            }
        };
        let key = (
            unit.clone(),
            series_kind,
            set_point_celsius.to_bits(),
            series,
            repeat,
            activation,
        );
        if let Some(first) = seen_labels.insert(key, row) {
            return Err(bad(
                "activation",
                format!(
                    "unit {unit}, {} series {series}, repeat {repeat}, activation {activation} at {set_point_celsius} °C is already in row {first}",
                    series_kind.as_str()
                ),
            ));
        }
        rows.push(SheetRow {
            file,
            unit,
            set_point_celsius,
            switch_on_ambient_celsius,
            series,
            repeat,
            activation,
            off_before_s,
            interval_min,
            series_kind,
            switch_on_ns,
            at: (row, line),
        });
    }
    if rows.is_empty() {
        return Err(SheetError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok(rows)
}

/// How far the sensor's temperature at switch-on may lie below and above the chamber's, °C.
#[derive(Debug, Clone, Copy)]
struct SwitchOnBand {
    below: f64,
    above: f64,
}

impl SwitchOnBand {
    /// A protocol's chamber is settled: a chamber still settling (5 °C below), heat left from the
    /// previous activation (30 °C above).
    const PROTOCOL: Self = Self {
        below: 5.0,
        above: 30.0,
    };
    /// A field session's unit may just have been carried to another ambient (up to 20 °C colder
    /// or warmer than it) and be warm from the previous activation: a file in °F still falls
    /// outside it from an ambient of about +16 °C up (1.8·T + 32 − T > 45), one in kelvin always.
    const FIELD: Self = Self {
        below: 20.0,
        above: 45.0,
    };

    fn of(kind: SeriesKind) -> Self {
        match kind {
            SeriesKind::Protocol => Self::PROTOCOL,
            SeriesKind::Field => Self::FIELD,
        }
    }
}

/// The activation's first temperature reading against the sheet's ambient: a label of another
/// set point, or a temperature in another unit than °C, is refused.
fn check_switch_on_temperature(
    segment: &Segment,
    ambient: f64,
    row: &SheetRow,
) -> Result<(), String> {
    let scale = segment.temperature_scale;
    let first = (0..3)
        .filter_map(|axis| {
            segment.temperature_raw[axis]
                .iter()
                .find(|&&r| r != crate::segment::TEMPERATURE_MISSING_RAW)
                .map(|&r| scale.celsius(f64::from(r)))
        })
        .fold(None, |m: Option<f64>, c| Some(m.map_or(c, |m| m.min(c))));
    let Some(celsius) = first else {
        return Ok(());
    };
    let band = SwitchOnBand::of(row.series_kind);
    if celsius < ambient - band.below || celsius > ambient + band.above {
        return Err(format!(
            "{ambient} °C, but the data of `{}` start at {celsius:.2} °C: a sensor switched on in this ambient ({} session) reads between {:.0} and {:.0} °C; the label is another set point's, or the file's temperature is not in °C (°F or kelvin: convert the file to °C)",
            row.file.display(),
            row.series_kind.as_str(),
            ambient - band.below,
            ambient + band.above
        ));
    }
    Ok(())
}

/// The recording a sheet row goes into: unit, series kind and set point.
fn recording_key(row: &SheetRow) -> (String, SeriesKind, u64) {
    (
        row.unit.clone(),
        row.series_kind,
        row.set_point_celsius.to_bits(),
    )
}

/// The file stem of the recording of a unit × set point × series kind, as the simulator names
/// them (`GIU-01_sp+30.0C_protocol`); the unit id made file-name safe.
pub fn recording_stem(unit: &str, set_point_celsius: f64, kind: SeriesKind) -> String {
    let unit: String = unit
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{unit}_sp{set_point_celsius:+.1}C_{}", kind.as_str())
}

/// Reads a sheet and every activation file it names into recordings, one per unit × set point ×
/// series kind (in order of first appearance; activations in sheet order), with `options`' column
/// mapping, units, timing and sample rate (its unit id, set point, series kind and activation
/// column are the sheet's). Activations of one recording must follow each other on the bench
/// clock; an activation without a switch-on time starts its off-time (or 1 s, when unknown) after
/// the previous one ends.
pub fn read_sheet_campaign(
    sheet: &Path,
    options: &CsvOptions,
) -> Result<Vec<(String, Recording)>, SheetError> {
    read_sheet_campaign_with(sheet, options, &|_, _| None)
}

/// What reads an activation file that is not CSV: `Some` with the activation's samples (or why
/// they cannot be read) for a file it knows (a ROS 2 bag, a ULog), `None` for a CSV file. It gets
/// the row's file and the CSV options with the row's unit, set point and series kind.
pub type LogReader<'a> = dyn Fn(&Path, &CsvOptions) -> Option<Result<Segment, Box<dyn std::error::Error + Send + Sync>>>
    + 'a;

/// [`read_sheet_campaign`], with `logs` reading the activation files that are logs of another
/// tool; each activation's labels are the sheet's whatever the file says.
pub fn read_sheet_campaign_with(
    sheet: &Path,
    options: &CsvOptions,
    logs: &LogReader<'_>,
) -> Result<Vec<(String, Recording)>, SheetError> {
    let rows = read_sheet(sheet)?;
    let mut order: Vec<(String, SeriesKind, u64)> = Vec::new();
    for row in &rows {
        let key = recording_key(row);
        if !order.contains(&key) {
            order.push(key);
        }
    }
    let stems: Vec<String> = order
        .iter()
        .map(|(unit, kind, bits)| recording_stem(unit, f64::from_bits(*bits), *kind))
        .collect();
    let distinct: BTreeSet<&String> = stems.iter().collect();
    if distinct.len() != stems.len() {
        return Err(SheetError::Sheet {
            path: sheet.to_path_buf(),
            reason: "two units or set points give the same recording name (unit ids differ only in characters other than letters, digits, `-`, `_`, `.`, or set points within 0.05 °C)".into(),
        });
    }
    let fs = options.sample_rate_hz;
    let period_ns = 1_000_000_000 / u64::from(fs.max(1));
    let mut recordings = Vec::new();
    // Per unit: each activation file's noise level with its row, to find a file in another unit.
    let mut levels: BTreeMap<String, Vec<(&SheetRow, Option<f64>)>> = BTreeMap::new();
    for (key, stem) in order.iter().zip(stems) {
        let (unit, kind, bits) = key;
        let set_point = f64::from_bits(*bits);
        let mut segments = Vec::new();
        let mut previous: Option<(u64, (u64, u64))> = None;
        for row in rows.iter().filter(|r| &recording_key(r) == key) {
            let (row_number, line) = row.at;
            let mut file_options = options.clone();
            file_options.columns.segment = None;
            file_options.unit_id = unit.clone();
            file_options.set_point_celsius =
                Some(row.switch_on_ambient_celsius.unwrap_or(set_point));
            file_options.series_kind = *kind;
            let segment = match logs(&row.file, &file_options) {
                Some(read) => Some(read.map_err(|source| SheetError::Log {
                    sheet: sheet.to_path_buf(),
                    row: row_number,
                    line,
                    source,
                })?),
                None => {
                    let read =
                        read_csv(&row.file, &file_options).map_err(|source| SheetError::File {
                            sheet: sheet.to_path_buf(),
                            row: row_number,
                            line,
                            source: Box::new(source),
                        })?;
                    read.segments.into_iter().next()
                }
            };
            let Some(mut segment) = segment else {
                return Err(SheetError::Row {
                    path: sheet.to_path_buf(),
                    row: row_number,
                    line,
                    column: "file".into(),
                    reason: format!("{}: no samples", row.file.display()),
                });
            };
            levels
                .entry(unit.clone())
                .or_default()
                .push((row, sheet_units::noise_level(&segment)));
            let end_of_previous = previous.map(|(end, _)| end);
            let power_on_ns = match (row.switch_on_ns, end_of_previous) {
                (Some(on), _) => on,
                (None, None) => 0,
                (None, Some(end)) => {
                    let off_ns = (row.off_before_s.unwrap_or(1.0) * 1e9).round().max(1.0) as u64;
                    end.saturating_add(off_ns)
                }
            };
            let ambient = row.switch_on_ambient_celsius.unwrap_or(set_point);
            check_switch_on_temperature(&segment, ambient, row).map_err(|reason| {
                SheetError::Row {
                    path: sheet.to_path_buf(),
                    row: row_number,
                    line,
                    column: if row.switch_on_ambient_celsius.is_some() {
                        "switch_on_ambient_celsius"
                    } else {
                        "set_point_celsius"
                    }
                    .into(),
                    reason,
                }
            })?;
            if let Some((end, (prev_row, _))) = previous {
                if power_on_ns <= end {
                    return Err(SheetError::Row {
                        path: sheet.to_path_buf(),
                        row: row_number,
                        line,
                        column: "switch_on_s".into(),
                        reason: format!(
                            "switch-on at {} s is not after the end of the previous activation of unit {unit} at {set_point} °C ({}, row {prev_row}, ends at {} s): list each recording's activations in time order",
                            power_on_ns as f64 / 1e9,
                            kind.as_str(),
                            end as f64 / 1e9
                        ),
                    });
                }
                if let (Some(off), Some(_)) = (row.off_before_s, row.switch_on_ns) {
                    let gap = power_on_ns.saturating_sub(end) as f64 * 1e-9;
                    if (off - gap).abs() > (0.05 * gap).max(1.0) {
                        return Err(SheetError::Row {
                            path: sheet.to_path_buf(),
                            row: row_number,
                            line,
                            column: "off_before_s".into(),
                            reason: format!(
                                "{off} s, but `switch_on_s` puts this switch-on {gap:.1} s after the end of the previous activation (row {prev_row}); correct one of them"
                            ),
                        });
                    }
                }
            }
            segment.power_on_ns = power_on_ns;
            // The chamber's set point as the format's own channel, constant over the activation:
            // what the sheet knows of it (a bench logging it would give it per sample).
            if fs % AUX_RATE_HZ == 0 {
                let every = (fs / AUX_RATE_HZ) as usize;
                segment.aux.insert(
                    SET_POINT_CHANNEL.into(),
                    AuxChannel {
                        unit: fixed_aux_unit(SET_POINT_CHANNEL).unwrap_or("degC").into(),
                        sample_rate_hz: AUX_RATE_HZ,
                        values: vec![ambient as f32; segment.len().div_ceil(every)],
                    },
                );
            }
            let labels = &mut segment.labels;
            labels.set_point_celsius = ambient;
            labels.session_set_point_celsius =
                row.switch_on_ambient_celsius.is_some().then_some(set_point);
            labels.series = row.series;
            labels.repeat = row.repeat;
            labels.activation = row.activation;
            labels.interval_min = row.interval_min;
            labels.off_before_s = row.off_before_s;
            let end = (segment.len() as u64)
                .checked_mul(period_ns)
                .and_then(|d| power_on_ns.checked_add(d))
                .ok_or_else(|| SheetError::Row {
                    path: sheet.to_path_buf(),
                    row: row_number,
                    line,
                    column: "switch_on_s".into(),
                    reason: "the activation ends beyond the recording clock".into(),
                })?;
            previous = Some((end, row.at));
            segments.push(segment);
        }
        // The reader gives the session set point only where it differs from the switch-on one.
        for segment in &mut segments {
            if segment.labels.session_set_point_celsius == Some(segment.labels.set_point_celsius) {
                segment.labels.session_set_point_celsius = None;
            }
        }
        let timed = rows
            .iter()
            .filter(|r| &recording_key(r) == key)
            .all(|r| r.switch_on_ns.is_some());
        let metadata = [
            ("format_version", crate::schema::FORMAT_VERSION.to_owned()),
            ("unit_id", unit.clone()),
            ("set_point_celsius", format!("{set_point}")),
            ("series_kind", kind.as_str().to_owned()),
            ("sample_rate_hz", fs.to_string()),
            ("temperature_raw_per_celsius", format!("{RAW_PER_CELSIUS}")),
            ("source", format!("activation sheet: {}", sheet.display())),
            (
                "clock",
                if timed {
                    "log_time = the sheet's switch_on_s (bench clock)".to_owned()
                } else {
                    "log_time = the sheet's switch_on_s where given, else laid out from off_before_s".to_owned()
                },
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
        recordings.push((
            stem,
            Recording {
                path: PathBuf::new(),
                metadata,
                unit_id: unit.clone(),
                sample_rate_hz: fs,
                segments,
            },
        ));
    }
    for (unit, files) in &levels {
        let found: Vec<Option<f64>> = files.iter().map(|(_, level)| *level).collect();
        if let Some((i, ratio, median)) = sheet_units::odd_one_out(&found) {
            let row = files[i].0;
            return Err(SheetError::Row {
                path: sheet.to_path_buf(),
                row: row.at.0,
                line: row.at.1,
                column: "file".into(),
                reason: format!(
                    "the rate of `{}` changes from sample to sample by {:.3e} °/s on average, {} the median of unit {unit}'s {} other files ({median:.3e} °/s): {}. One `--rate-unit` reads every file of the sheet: convert this file to the others' unit",
                    row.file.display(),
                    ratio * median,
                    if ratio < 1.0 {
                        format!("{:.0}× less than", 1.0 / ratio)
                    } else {
                        format!("{ratio:.0}× more than")
                    },
                    files.len() - 1,
                    sheet_units::likely_cause(ratio)
                ),
            });
        }
    }
    Ok(recordings)
}
