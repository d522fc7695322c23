//! The main job, one way through: recordings → segments → fitted tables → corrector → residual →
//! report data.
//!
//! Recordings are read twice, file by file. The first pass decodes the calibration files one
//! activation at a time on a thread of its own and analyses each activation (into small curves for
//! the fits) as it arrives, so memory holds one file's bytes and a few activations' samples; the
//! second holds one file's samples at a time and corrects every activation the fits did not see.
//! Validation set points, field sessions and the noise-floor unit never reach a fit; at
//! calibration set points each repeat is evaluated with tables refitted without it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, sync_channel, Receiver};
use std::time::Instant;

use drift_recording::{
    block_means, paper, read_metadata, read_recording_with, Interrupted, OpenRecording, ReadError,
    Recording, Segment, SeriesKind, Within, COMPLETION_MARKER, RECORDINGS_DIR, TRUTH_DIR,
};
use rayon::prelude::*;

use crate::coverage::{self, UnitCoverage};
use crate::evaluate::{evaluate_at, kept_before, ActivationResult};
use crate::summary::Split;
use crate::uncertainty::{self, Residuals, UnitUncertainty};
use drift_fit::analyse::{analyse, Analysed};
use drift_fit::error::FitError;
use drift_fit::fit::{fit_unit, FittedUnit};
use drift_fit::settings::FitSettings;

/// Why the pipeline stopped.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// A folder could not be listed.
    #[error("listing recordings in {path}: {source}")]
    List {
        /// The folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A simulated campaign folder without the file its simulation writes last.
    #[error("{path} is an incomplete simulated campaign (no {marker}, which `simulate` writes last): the simulation stopped part-way; simulate it again with --force")]
    Incomplete {
        /// The campaign folder.
        path: PathBuf,
        /// The completion marker's name.
        marker: &'static str,
    },
    /// A folder holds no recordings.
    #[error("no .mcap recordings in {path}")]
    NoRecordings {
        /// The folder.
        path: PathBuf,
    },
    /// A recording failed to read or validate (the error names file, topic and message).
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Stopped by its [`Progress`] (Ctrl-C in Python).
    #[error("interrupted")]
    Interrupted(#[from] Interrupted),
    /// Analysing or fitting failed (the error names the unit and activation).
    #[error(transparent)]
    Fit(#[from] FitError),
    /// No unit of the evaluation data was fitted on the calibration data.
    #[error("no unit of the evaluation data ({evaluated}) was fitted on the calibration data (fitted: {fitted}): the evaluation data must be recordings of the fitted units")]
    NoFittedUnit {
        /// Unit ids of the evaluation data, comma-separated.
        evaluated: String,
        /// Unit ids fitted, comma-separated.
        fitted: String,
    },
    /// A noise-floor unit has no calibration activations of its own, and no unit of its id was
    /// fitted.
    #[error("noise-floor unit {unit} has no protocol activations at the calibration set points {set_points:?} °C, and no unit of that id was fitted to take the tables from")]
    NoiseFloorUnfitted {
        /// The noise-floor unit.
        unit: String,
        /// The calibration set points asked for.
        set_points: Vec<f64>,
    },
    /// A set point asked for both as calibration and as validation: its rows would be labelled
    /// validation while the fit saw them.
    #[error("{set_point:+} °C is both a calibration and a validation set point: its activations are in the fit, so they cannot validate it; choose a validation set point the calibration does not list")]
    CalibrationIsValidation {
        /// The set point in both lists, °C.
        set_point: f64,
    },
    /// A unit lacks protocol activations at one of the calibration set points: its tables would
    /// cover fewer ambients than asked for (a half-recorded or half-simulated campaign).
    #[error("{unit}: no protocol activations at the calibration set point {set_point:+} °C (it has {}); record it, or leave it out of the calibration set points", list_set_points(found))]
    MissingCalibration {
        /// The unit.
        unit: String,
        /// The calibration set point without activations, °C.
        set_point: f64,
        /// The calibration set points the unit has, °C.
        found: Vec<f64>,
    },
    /// A validation set point without a single activation: nothing would be validated there.
    #[error("no activations at the validation set point {set_point:+} °C in {files} recordings (set points recorded: {}); choose validation set points from those", list_set_points(found))]
    MissingValidation {
        /// The validation set point without activations, °C.
        set_point: f64,
        /// The nominal set points of the recordings, °C.
        found: Vec<f64>,
        /// How many recordings were looked at.
        files: usize,
    },
    /// A recording to evaluate gives its unit's temperature sensor another scale than the
    /// calibration recordings the tables were fitted on: the tables would read its temperatures
    /// wrong.
    #[error("{path}: temperature scale {raw_per_celsius} raw/°C, {raw_at_zero_celsius} raw at 0 °C, but unit {unit}'s tables were fitted on recordings at {tables_per_celsius} raw/°C, {tables_at_zero} raw at 0 °C (metadata temperature_raw_per_celsius, temperature_raw_at_zero_celsius): record both at one scale, or correct the metadata")]
    OtherTemperatureScale {
        /// The recording.
        path: PathBuf,
        /// The unit.
        unit: String,
        /// The recording's scale, raw units per °C.
        raw_per_celsius: f64,
        /// The recording's raw reading at 0 °C.
        raw_at_zero_celsius: f64,
        /// The tables' scale, raw units per °C.
        tables_per_celsius: f32,
        /// The tables' raw reading at 0 °C.
        tables_at_zero: f32,
    },
    /// An activation to evaluate lacks the channel named for the ambient at switch-on, or has no
    /// finite value of it there.
    #[error("{path}: {activation}: no finite `{channel}` value at switch-on, which --switch-on-ambient reads as the ambient (channels logged: {found}); name a channel every evaluated recording logs")]
    NoSwitchOnAmbient {
        /// The recording.
        path: PathBuf,
        /// The activation: unit, nominal set point, series kind, series and index.
        activation: String,
        /// The channel named.
        channel: String,
        /// The auxiliary channels it has, comma-separated, or `none`.
        found: String,
    },
    /// None of the recordings has protocol activations at the calibration set points.
    #[error("no protocol activations at the calibration set points {set_points:?} °C in {files} recordings")]
    NoCalibration {
        /// The calibration set points asked for.
        set_points: Vec<f64>,
        /// How many recordings were looked at.
        files: usize,
    },
}

/// Set points as `+30, +40 °C`, or `none`.
fn list_set_points(set_points: &[f64]) -> String {
    if set_points.is_empty() {
        return "none".into();
    }
    let list: Vec<String> = set_points.iter().map(|s| format!("{s:+}")).collect();
    format!("{} °C", list.join(", "))
}

/// Adds `set_point` to `list` unless it is already one of them (to a micro-degree); keeps it sorted.
fn note_set_point(list: &mut Vec<f64>, set_point: f64) {
    if !is_one_of(set_point, list) {
        list.push(set_point);
        list.sort_by(f64::total_cmp);
    }
}

/// What to fit on and what to evaluate on.
#[derive(Debug, Clone)]
pub struct Options {
    /// Chamber set points whose protocol activations are fitted, °C.
    pub calibration_set_points: Vec<f64>,
    /// Chamber set points evaluated only, °C (never fitted).
    pub validation_set_points: Vec<f64>,
    /// Fitting settings.
    pub fit: FitSettings,
    /// Evaluate each repeat at the calibration set points with tables refitted without it.
    pub held_out_repeats: bool,
    /// Run the evaluation pass at all (`false`: fit only; nothing else is read).
    pub evaluate: bool,
    /// A logged channel that holds the ambient the instrument measured, read at each evaluated
    /// activation's switch-on: the paper's tables are also evaluated started there
    /// ([`crate::evaluate::ModelKind::AtAmbient`]). Every evaluated activation must log it.
    pub switch_on_ambient: Option<String>,
}

impl Default for Options {
    /// The paper's campaign: fit on its calibration set points, validate on its validation set
    /// point, default fit settings, every evaluation.
    fn default() -> Self {
        Self {
            calibration_set_points: paper::CALIBRATION_SET_POINTS_CELSIUS.to_vec(),
            validation_set_points: vec![paper::VALIDATION_SET_POINT_CELSIUS],
            fit: FitSettings::default(),
            held_out_repeats: true,
            evaluate: true,
            switch_on_ambient: None,
        }
    }
}

/// Everything the report needs.
#[derive(Debug, Default)]
pub struct Outcome {
    /// Tables fitted on all calibration activations, per unit.
    pub fitted: Vec<FittedUnit>,
    /// The calibration activations, analysed.
    pub calibration: Vec<Analysed>,
    /// Evaluation results with their split.
    pub results: Vec<(Split, ActivationResult)>,
    /// Step durations, seconds.
    pub timings: Vec<(String, f64)>,
    /// Samples read in the first pass.
    pub samples_read: u64,
    /// σ(t) of the recommended model per unit, fitted on the held-out repeats, with how often
    /// validation and field residuals fell within ±2σ.
    pub uncertainty: Vec<UnitUncertainty>,
    /// The coverage map per unit: the calibration's switch-on temperatures × residual heats and
    /// the held-out data outside the envelope.
    pub coverage: Vec<UnitCoverage>,
}

/// Told how far the pipeline got, between files and activations, and asked whether to go on: a
/// closure `Fn(step, done, total)` listens; a [`drift_recording::Progress`] of its own may stop
/// the run ([`PipelineError::Interrupted`]).
pub type Progress<'a> = &'a dyn drift_recording::Progress;

/// Whether `set_point` (°C) is one of `list`, to a micro-degree.
pub fn is_one_of(set_point: f64, list: &[f64]) -> bool {
    list.iter().any(|s| (s - set_point).abs() < 1e-6)
}

/// The recordings of a campaign folder (or of a folder of `.mcap` files), sorted by name.
///
/// A simulated campaign (a folder with `truth/`) must have its completion marker
/// ([`drift_recording::COMPLETION_MARKER`]): half a campaign is refused, not fitted.
pub fn recording_files(dir: &Path) -> Result<Vec<PathBuf>, PipelineError> {
    if dir.join(TRUTH_DIR).is_dir() && !dir.join(COMPLETION_MARKER).is_file() {
        return Err(PipelineError::Incomplete {
            path: dir.to_path_buf(),
            marker: COMPLETION_MARKER,
        });
    }
    let folder = if dir.join(RECORDINGS_DIR).is_dir() {
        dir.join(RECORDINGS_DIR)
    } else {
        dir.to_path_buf()
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .map_err(|source| PipelineError::List {
            path: folder.clone(),
            source,
        })?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|e| e == "mcap") && !drift_recording::is_truth_path(p)
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(PipelineError::NoRecordings { path: folder });
    }
    Ok(files)
}

/// What a recording's metadata says about it, without decoding a message: `Some(true)` for a
/// protocol recording at a calibration set point, `Some(false)` for any other, `None` when the
/// metadata lacks the set point or series kind (then the segments' own labels must decide).
pub fn calibration_file(path: &Path, options: &Options) -> Result<Option<bool>, PipelineError> {
    Ok(calibration_metadata(&read_metadata(path)?, options))
}

/// [`calibration_file`] from metadata already read.
pub fn calibration_metadata(
    metadata: &BTreeMap<String, String>,
    options: &Options,
) -> Option<bool> {
    let set_point = metadata
        .get("set_point_celsius")
        .and_then(|s| s.parse::<f64>().ok());
    let kind = metadata
        .get("series_kind")
        .and_then(|s| SeriesKind::parse(s));
    set_point.zip(kind).map(|(set_point, kind)| {
        kind == SeriesKind::Protocol && is_one_of(set_point, &options.calibration_set_points)
    })
}

/// Whether an activation is calibration data: a protocol activation at a calibration set point.
///
/// This goes by the chamber set point at switch-on, the label the fit groups curves by
/// (`curves.rs`): protocol sessions do not ramp, so it is also the recording's nominal one.
/// Validation, field and noise-floor membership go by the nominal set point
/// ([`drift_recording::SegmentLabels::nominal_set_point_celsius`]) instead.
pub fn calibration_segment(segment: &Segment, options: &Options) -> bool {
    segment.labels.series_kind == SeriesKind::Protocol
        && is_one_of(
            segment.labels.set_point_celsius,
            &options.calibration_set_points,
        )
}

/// The prefix that tells a noise-floor unit's results apart from the fitted units' (`noise:GIU-01`).
pub const NOISE_FLOOR_PREFIX: &str = "noise:";

/// [`run`] on `files`, then, with `noise_floor`, on a campaign of zero-drift twins measured the
/// same way: their results are added with their unit ids prefixed by [`NOISE_FLOOR_PREFIX`], and
/// their timings by "noise floor: ". Returns the outcome and the noise-floor unit ids, in order of
/// first appearance.
pub fn run_with_noise_floor(
    files: &[PathBuf],
    noise_floor: Option<&[PathBuf]>,
    options: &Options,
    progress: Progress<'_>,
) -> Result<(Outcome, Vec<String>), PipelineError> {
    let outcome = run(files, options, false, progress)?;
    let validation = options.validation_set_points.clone();
    add_noise_floor(outcome, noise_floor, options, &validation, progress)
}

/// Fits on the calibration activations of `calibration` (protocol activations at the calibration
/// set points) and evaluates every activation of `evaluation`, a separate source none of which
/// reaches a fit: protocol activations as [`Split::Validation`] at whatever set point, field
/// sessions as [`Split::Field`]. Activations of units not fitted are skipped (at least one unit
/// must match). With `noise_floor`, a campaign of zero-drift twins is evaluated at the set points
/// of the evaluation data ([`run_with_noise_floor`]); a twin recorded only there is corrected with
/// the tables fitted for the unit of its id. `options.validation_set_points` and
/// `options.held_out_repeats` are not used.
pub fn run_separate(
    calibration: &[PathBuf],
    evaluation: &[PathBuf],
    noise_floor: Option<&[PathBuf]>,
    options: &Options,
    progress: Progress<'_>,
) -> Result<(Outcome, Vec<String>), PipelineError> {
    let fit_only = Options {
        held_out_repeats: false,
        evaluate: false,
        ..options.clone()
    };
    let mut outcome = run(calibration, &fit_only, false, progress)?;
    let started = Instant::now();
    let mut evaluated_units = BTreeSet::new();
    let fitted = &outcome.fitted;
    let ambient = options.switch_on_ambient.as_deref();
    let results = evaluate_files(
        evaluation,
        &options.fit,
        ambient,
        progress,
        |unit, segment| {
            evaluated_units.insert(unit.to_owned());
            let model = fitted.iter().find(|f| f.unit_id == unit)?;
            let split = if segment.labels.series_kind == SeriesKind::Field {
                Split::Field
            } else {
                Split::Validation
            };
            Some((split, model))
        },
    )?;
    if results.is_empty() && !evaluated_units.is_empty() {
        return Err(PipelineError::NoFittedUnit {
            evaluated: evaluated_units.into_iter().collect::<Vec<_>>().join(", "),
            fitted: fitted
                .iter()
                .map(|f| f.unit_id.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    outcome.results = results;
    outcome.timings.push((
        "read the evaluation data, correct and evaluate".into(),
        started.elapsed().as_secs_f64(),
    ));
    let mut set_points: Vec<f64> = Vec::new();
    for (_, result) in &outcome.results {
        let s = result.labels.nominal_set_point_celsius();
        if !is_one_of(s, &set_points) {
            set_points.push(s);
        }
    }
    add_noise_floor(outcome, noise_floor, options, &set_points, progress)
}

/// Adds the noise-floor twins' results (every activation at one of `set_points`, nominal) to
/// `outcome`, their unit ids prefixed by [`NOISE_FLOOR_PREFIX`]: each twin corrected with its own
/// tables when its recordings have calibration activations, else with the tables of the fitted
/// unit of its id.
fn add_noise_floor(
    mut outcome: Outcome,
    noise_floor: Option<&[PathBuf]>,
    options: &Options,
    set_points: &[f64],
    progress: Progress<'_>,
) -> Result<(Outcome, Vec<String>), PipelineError> {
    let mut noise_units = Vec::new();
    let Some(noise_files) = noise_floor else {
        return Ok((outcome, noise_units));
    };
    let own = Options {
        held_out_repeats: false,
        evaluate: false,
        ..options.clone()
    };
    let noise = match run(noise_files, &own, true, progress) {
        Ok(noise) => noise,
        // Recorded at the evaluation set points only: the fitted units' tables.
        Err(PipelineError::NoCalibration { .. }) => Outcome::default(),
        Err(e) => return Err(e),
    };
    let started = Instant::now();
    let mut missing = None;
    let ambient = options.switch_on_ambient.as_deref();
    let results = evaluate_files(
        noise_files,
        &options.fit,
        ambient,
        progress,
        |unit, segment| {
            let model = noise
                .fitted
                .iter()
                .chain(&outcome.fitted)
                .find(|f| f.unit_id == unit);
            if model.is_none() {
                missing.get_or_insert_with(|| unit.to_owned());
            }
            is_one_of(segment.labels.nominal_set_point_celsius(), set_points)
                .then_some((Split::NoiseFloor, model?))
        },
    )?;
    if let Some(unit) = missing {
        return Err(PipelineError::NoiseFloorUnfitted {
            unit,
            set_points: options.calibration_set_points.clone(),
        });
    }
    for (split, mut result) in results {
        result.labels.unit_id = format!("{NOISE_FLOOR_PREFIX}{}", result.labels.unit_id);
        if !noise_units.contains(&result.labels.unit_id) {
            noise_units.push(result.labels.unit_id.clone());
        }
        outcome.results.push((split, result));
    }
    outcome.timings.extend(
        noise
            .timings
            .into_iter()
            .map(|(step, seconds)| (format!("noise floor: {step}"), seconds)),
    );
    outcome.timings.push((
        "noise floor: read again, correct and evaluate".into(),
        started.elapsed().as_secs_f64(),
    ));
    Ok((outcome, noise_units))
}

/// Reads `files` one at a time and evaluates the activations `choose` gives a split and tables
/// for (by unit id and activation), each after what firmware kept of the activations before it in
/// its recording; results in file and activation order.
fn evaluate_files<'a>(
    files: &[PathBuf],
    settings: &FitSettings,
    ambient_channel: Option<&str>,
    progress: Progress<'_>,
    mut choose: impl FnMut(&str, &Segment) -> Option<(Split, &'a FittedUnit)>,
) -> Result<Vec<(Split, ActivationResult)>, PipelineError> {
    let mut out = Vec::new();
    let total = files.len() as u64;
    for (i, path) in files.iter().enumerate() {
        let done = i as u64;
        progress.check(EVALUATE_STEP, done, total)?;
        let recording = read_recording_with(path, &within(progress, EVALUATE_STEP, done, total))?;
        let chosen: Vec<Option<(Split, &FittedUnit)>> = recording
            .segments
            .iter()
            .map(|s| choose(&recording.unit_id, s))
            .collect();
        let Some(by_history) = chosen
            .iter()
            .flatten()
            .map(|(_, f)| &f.by_history.settings)
            .next()
        else {
            continue;
        };
        let mut ambients = Vec::with_capacity(chosen.len());
        for (segment, chosen) in recording.segments.iter().zip(&chosen) {
            if let Some((_, fitted)) = chosen {
                same_scale(&recording, segment, fitted)?;
                ambients.push(switch_on_ambient(
                    path,
                    &recording,
                    segment,
                    ambient_channel,
                )?);
            } else {
                ambients.push(None);
            }
        }
        let segments: Vec<&Segment> = recording.segments.iter().collect();
        let kept = kept_before(&segments, settings, by_history, true);
        let results: Vec<(Split, ActivationResult)> = recording
            .segments
            .par_iter()
            .zip(kept.par_iter())
            .zip(chosen.par_iter().zip(ambients.par_iter()))
            .filter_map(|((segment, previous), (chosen, &ambient))| {
                let (split, model) = (*chosen)?;
                let result = evaluate_at(model, segment, settings, previous, ambient);
                Some((split, result))
            })
            .collect();
        out.extend(results);
    }
    progress.check(EVALUATE_STEP, total, total)?;
    Ok(out)
}

/// The ambient `segment` (of the recording at `path`) logged on `channel` at switch-on, °C (its
/// first value); `None` without a channel named, an error naming the activation without a finite
/// value.
fn switch_on_ambient(
    path: &Path,
    recording: &Recording,
    segment: &Segment,
    channel: Option<&str>,
) -> Result<Option<f32>, PipelineError> {
    let Some(channel) = channel else {
        return Ok(None);
    };
    if let Some(value) = segment.aux_at_switch_on(channel) {
        return Ok(Some(value));
    }
    let labels = &segment.labels;
    let found: Vec<&str> = segment.aux.keys().map(String::as_str).collect();
    Err(PipelineError::NoSwitchOnAmbient {
        path: path.to_path_buf(),
        activation: format!(
            "unit {}, set point {:+} °C, {} series {} activation {}",
            recording.unit_id,
            labels.nominal_set_point_celsius(),
            labels.series_kind.as_str(),
            labels.series,
            labels.activation
        ),
        channel: channel.to_owned(),
        found: if found.is_empty() {
            "none".into()
        } else {
            found.join(", ")
        },
    })
}

/// Refuses `segment` (of `recording`) when its temperature scale is not the one `fitted`'s tables
/// convert raw readings with.
fn same_scale(
    recording: &Recording,
    segment: &Segment,
    fitted: &FittedUnit,
) -> Result<(), PipelineError> {
    let tables = fitted.modified.settings;
    let scale = segment.temperature_scale;
    if scale.raw_per_celsius as f32 == tables.raw_per_celsius
        && scale.raw_at_zero_celsius as f32 == tables.raw_at_zero_celsius
    {
        return Ok(());
    }
    Err(PipelineError::OtherTemperatureScale {
        path: recording.path.clone(),
        unit: recording.unit_id.clone(),
        raw_per_celsius: scale.raw_per_celsius,
        raw_at_zero_celsius: scale.raw_at_zero_celsius,
        tables_per_celsius: tables.raw_per_celsius,
        tables_at_zero: tables.raw_at_zero_celsius,
    })
}

/// The progress step of pass 2.
const EVALUATE_STEP: &str = "correcting and evaluating";

/// A [`Progress`] for reading one file of `step`: the step's position is kept, and the reading
/// stops between activations when `progress` asks.
fn within<'a>(progress: Progress<'a>, step: &'a str, done: u64, total: u64) -> Within<'a> {
    Within {
        outer: progress,
        step,
        done,
        total,
    }
}

/// The progress step of pass 1.
const READ_STEP: &str = "reading and analysing calibration recordings";

/// How many decoded activations may wait for their analysis: enough to ride out an analysis
/// that falls behind for a moment, few enough that memory holds a handful of activations, never a
/// recording's worth.
const ACTIVATIONS_IN_FLIGHT: usize = 4;

/// Stack of the threads that fit a unit early: fitted tables are large values, and the fit holds
/// several at once (see `STACK_BYTES` in the command's `main.rs`). Only what is touched is
/// committed.
const FIT_STACK_BYTES: usize = 64 << 20;

/// One activation's split, result and (but for the noise floor) its residual for σ(t).
type Evaluated = (Split, ActivationResult, Option<Residuals>);

/// A unit's tables from all its calibration activations, and the refits per left-out repeat.
type UnitFits = (FittedUnit, Vec<(u32, FittedUnit)>);

/// Fits `analysed` (one unit's calibration activations, in file order) and, with
/// `options.held_out_repeats` and more than one repeat, once more without each repeat.
fn fit_with_refits(analysed: &[Analysed], options: &Options) -> Result<UnitFits, FitError> {
    let all = fit_unit(analysed, &options.fit)?;
    let mut refits = Vec::new();
    if options.held_out_repeats {
        let repeats: BTreeSet<u32> = analysed.iter().map(|a| a.labels.repeat).collect();
        if repeats.len() > 1 {
            for &repeat in &repeats {
                let rest: Vec<Analysed> = analysed
                    .iter()
                    .filter(|a| a.labels.repeat != repeat)
                    .cloned()
                    .collect();
                refits.push((repeat, fit_unit(&rest, &options.fit)?));
            }
        }
    }
    Ok((all, refits))
}

/// The error for a unit whose activations lack one of the calibration set points, if they do.
fn missing_calibration(
    unit: &str,
    analysed: &[Analysed],
    options: &Options,
) -> Option<PipelineError> {
    let mut found = Vec::new();
    for a in analysed {
        note_set_point(&mut found, a.labels.set_point_celsius);
    }
    let set_point = *options
        .calibration_set_points
        .iter()
        .find(|s| !is_one_of(**s, &found))?;
    Some(PipelineError::MissingCalibration {
        unit: unit.to_owned(),
        set_point,
        found,
    })
}

/// What the reading thread hands the analysing one, in file order.
enum Decoded {
    /// A calibration file's activations follow: its unit.
    File(String),
    /// A calibration activation of that file (boxed: the channel's slots are as large as the
    /// largest message), with the rate it was recorded at (its block means' may be lower).
    Activation(Box<Segment>, u32),
    /// The file was read whole and is valid: the samples of all its activations.
    End(u64),
    /// Why a file could not be read; nothing follows.
    Failed(PipelineError),
}

/// Pass 1's result.
struct PassOne {
    /// The calibration activations, analysed, per unit in file and activation order.
    by_unit: BTreeMap<String, Vec<Analysed>>,
    /// Fits started while later files were read: how many activations each saw, and its result.
    early_fits: BTreeMap<String, (usize, Result<UnitFits, FitError>)>,
    samples_read: u64,
    read_seconds: f64,
    analyse_seconds: f64,
}

/// Reads `files` in order on one thread and analyses their calibration activations on the
/// calling one as they arrive, so the analysis hides behind the decoding, and memory holds one
/// file's bytes and a few activations, not a recording's samples. The activations reach the
/// analysis in file and activation order whatever the threads' timing, so the fits see exactly
/// what a file-by-file reading gives them; and the first fault in that order is the error: a file
/// that fails to read wins over an activation of it that fails to analyse, as when each file was
/// read whole before its analysis.
///
/// When a calibration file of another unit begins, the unit before it is fitted on a thread of
/// its own while the reading goes on: files are usually grouped by unit (sorted by name), and if
/// the unit comes back later the early fit is not used.
fn read_and_analyse(
    files: &[PathBuf],
    options: &Options,
    fit_rate_hz: Option<u32>,
    progress: Progress<'_>,
) -> Result<PassOne, PipelineError> {
    let (sender, receiver) = sync_channel(ACTIVATIONS_IN_FLIGHT);
    std::thread::scope(|scope| {
        let reader = std::thread::Builder::new()
            .name("gyrodrift-read".into())
            .spawn_scoped(scope, move || {
                read_calibration(files, options, fit_rate_hz, progress, |d| {
                    sender.send(d).is_ok()
                })
            });
        let reader = match reader {
            Ok(reader) => reader,
            // Without a second thread, read everything on this one first (the same activations
            // in the same order, all in memory at once), then analyse.
            Err(_) => {
                let (sender, receiver) = channel();
                let read_seconds = read_calibration(files, options, fit_rate_hz, progress, |d| {
                    sender.send(d).is_ok()
                });
                drop(sender);
                let mut pass = analyse_calibration(receiver, options, |_, _| {});
                if let Ok(pass) = &mut pass {
                    pass.read_seconds = read_seconds;
                }
                return pass;
            }
        };
        let mut early = Vec::new();
        let mut pass = analyse_calibration(receiver, options, |unit, analysed| {
            let snapshot = analysed.to_vec();
            let fit = std::thread::Builder::new()
                .name("gyrodrift-fit".into())
                .stack_size(FIT_STACK_BYTES)
                .spawn_scoped(scope, move || {
                    let fits = fit_with_refits(&snapshot, options);
                    (snapshot.len(), fits)
                });
            // Without a thread, the unit is fitted after the reading, as any other.
            if let Ok(fit) = fit {
                early.push((unit.to_owned(), fit));
            }
        });
        let read_seconds = reader
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        let early_fits: BTreeMap<String, (usize, Result<UnitFits, FitError>)> = early
            .into_iter()
            .map(|(unit, fit)| {
                let fit = fit
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
                (unit, fit)
            })
            .collect();
        if let Ok(pass) = &mut pass {
            pass.read_seconds = read_seconds;
            pass.early_fits = early_fits;
        }
        pass
    })
}

/// Pass 1's reading half: each file's metadata, then the calibration files decoded activation by
/// activation into `send`, until the end, a file that fails, or `send` returns `false` (the
/// analysis stopped listening). Returns the seconds it took.
fn read_calibration(
    files: &[PathBuf],
    options: &Options,
    fit_rate_hz: Option<u32>,
    progress: Progress<'_>,
    mut send: impl FnMut(Decoded) -> bool,
) -> f64 {
    let started = Instant::now();
    let total = files.len() as u64;
    for (i, path) in files.iter().enumerate() {
        let done = i as u64;
        if let Err(stop) = progress.check(READ_STEP, done, total) {
            send(Decoded::Failed(stop.into()));
            break;
        }
        let file = match OpenRecording::open(path) {
            Ok(file) => file,
            Err(e) => {
                send(Decoded::Failed(e.into()));
                break;
            }
        };
        if calibration_metadata(file.metadata(), options) == Some(false) {
            // Validation and field recordings are never decoded for the fit.
            continue;
        }
        if !send(Decoded::File(file.unit_id().to_owned())) {
            break;
        }
        let mut samples = 0;
        let read = file.for_each_activation_with(
            |segment| {
                samples += segment.len() as u64;
                if !calibration_segment(&segment, options) {
                    return true;
                }
                let recorded_hz = segment.sample_rate_hz;
                let segment = match fit_rate_hz {
                    Some(rate_hz) => block_means(&segment, rate_hz).unwrap_or(segment),
                    None => segment,
                };
                send(Decoded::Activation(Box::new(segment), recorded_hz))
            },
            &within(progress, READ_STEP, done, total),
        );
        match read {
            Ok(true) if send(Decoded::End(samples)) => {}
            Ok(_) => break,
            Err(e) => {
                send(Decoded::Failed(e.into()));
                break;
            }
        }
    }
    started.elapsed().as_secs_f64()
}

/// Pass 1's analysing half: analyses the activations from `receiver` in the order they come,
/// keeping a file's only once the whole file has read valid. Calls `unit_done` with a unit and
/// its activations when a file of another unit begins, if the unit has every calibration set
/// point and was not handed over before.
fn analyse_calibration(
    receiver: Receiver<Decoded>,
    options: &Options,
    mut unit_done: impl FnMut(&str, &[Analysed]),
) -> Result<PassOne, PipelineError> {
    let mut pass = PassOne {
        by_unit: BTreeMap::new(),
        early_fits: BTreeMap::new(),
        samples_read: 0,
        read_seconds: 0.0,
        analyse_seconds: 0.0,
    };
    let mut unit = String::new();
    let mut handed_over = BTreeSet::new();
    let mut file: Vec<Analysed> = Vec::new();
    let mut failed: Option<FitError> = None;
    for decoded in receiver {
        match decoded {
            Decoded::File(next) => {
                if next != unit {
                    if let Some(analysed) = pass.by_unit.get(&unit) {
                        if missing_calibration(&unit, analysed, options).is_none()
                            && handed_over.insert(unit.clone())
                        {
                            unit_done(&unit, analysed);
                        }
                    }
                }
                unit = next;
            }
            Decoded::Activation(segment, recorded_hz) => {
                if failed.is_some() {
                    continue;
                }
                let started = Instant::now();
                match analyse(&segment, &options.fit) {
                    // The tables state the rate firmware samples at, not the fit's.
                    Ok(analysed) => file.push(Analysed {
                        sample_rate_hz: recorded_hz,
                        ..analysed
                    }),
                    Err(e) => failed = Some(e),
                }
                pass.analyse_seconds += started.elapsed().as_secs_f64();
            }
            Decoded::End(samples) => {
                if let Some(e) = failed {
                    return Err(e.into());
                }
                pass.samples_read += samples;
                if !file.is_empty() {
                    pass.by_unit
                        .entry(unit.clone())
                        .or_default()
                        .append(&mut file);
                }
            }
            Decoded::Failed(e) => return Err(e),
        }
    }
    Ok(pass)
}

/// Fits every unit found in `files` and evaluates on everything the fits did not see.
/// With `noise_floor`, the units have no systematic drift: their validation results are labelled
/// [`Split::NoiseFloor`] and nothing else of theirs is evaluated.
pub fn run(
    files: &[PathBuf],
    options: &Options,
    noise_floor: bool,
    progress: Progress<'_>,
) -> Result<Outcome, PipelineError> {
    run_at(files, options, noise_floor, None, progress)
}

/// Fits every unit found in `files` as [`run`] does without evaluating, on each calibration
/// activation's block means at `rate_hz` ([`drift_recording::block_means`]; activations whose
/// rate is not a multiple of it as recorded): the closed loop's rate, so that the tables it
/// diagnoses are fitted on the activations as it sees them.
pub fn fit_at_rate(
    files: &[PathBuf],
    options: &Options,
    rate_hz: u32,
    progress: Progress<'_>,
) -> Result<Outcome, PipelineError> {
    let fit_only = Options {
        held_out_repeats: false,
        evaluate: false,
        ..options.clone()
    };
    run_at(files, &fit_only, false, Some(rate_hz), progress)
}

fn run_at(
    files: &[PathBuf],
    options: &Options,
    noise_floor: bool,
    fit_rate_hz: Option<u32>,
    progress: Progress<'_>,
) -> Result<Outcome, PipelineError> {
    let mut outcome = Outcome::default();
    let settings = &options.fit;
    if let Some(&set_point) = options
        .validation_set_points
        .iter()
        .find(|s| is_one_of(**s, &options.calibration_set_points))
    {
        return Err(PipelineError::CalibrationIsValidation { set_point });
    }

    // Pass 1: read and analyse the calibration activations, fitting each unit whose files are
    // all read while the next unit's are decoded.
    let pass = read_and_analyse(files, options, fit_rate_hz, progress)?;
    let total = files.len() as u64;
    progress.check(READ_STEP, total, total)?;
    outcome.samples_read = pass.samples_read;
    let (read_seconds, analyse_seconds) = (pass.read_seconds, pass.analyse_seconds);
    let by_unit = pass.by_unit;
    let mut early = pass.early_fits;

    // Units are entered only with analysed activations, so every entry is non-empty.
    if by_unit.is_empty() {
        return Err(PipelineError::NoCalibration {
            set_points: options.calibration_set_points.clone(),
            files: files.len(),
        });
    }

    // Every unit must have every calibration set point: tables fitted on fewer ambients than
    // asked for would be extrapolated silently.
    for (unit, analysed) in &by_unit {
        if let Some(missing) = missing_calibration(unit, analysed, options) {
            return Err(missing);
        }
    }

    // Fits: all calibration data, and one per left-out repeat; an early fit counts only if it
    // saw every activation of its unit.
    let started = Instant::now();
    let mut held_out: BTreeMap<(String, u32), FittedUnit> = BTreeMap::new();
    for (unit, analysed) in &by_unit {
        progress.check(READ_STEP, total, total)?;
        let fits = match early.remove(unit) {
            Some((seen, fits)) if seen == analysed.len() => fits,
            _ => fit_with_refits(analysed, options),
        };
        let (all, refits) = fits?;
        outcome.fitted.push(all);
        for (repeat, fitted) in refits {
            held_out.insert((unit.clone(), repeat), fitted);
        }
    }
    let fit_seconds = started.elapsed().as_secs_f64();

    // Pass 2: evaluate everything no fit saw.
    let started = Instant::now();
    let evaluated = if options.evaluate { files } else { &[] };
    let mut recorded_set_points = Vec::new();
    let mut residuals: Vec<(Split, Residuals)> = Vec::new();
    for (i, path) in evaluated.iter().enumerate() {
        let done = i as u64;
        progress.check(EVALUATE_STEP, done, total)?;
        let recording = read_recording_with(path, &within(progress, EVALUATE_STEP, done, total))?;
        for segment in &recording.segments {
            note_set_point(
                &mut recorded_set_points,
                segment.labels.nominal_set_point_celsius(),
            );
        }
        let Some(fitted) = outcome
            .fitted
            .iter()
            .find(|f| f.unit_id == recording.unit_id)
        else {
            continue;
        };
        // What firmware keeping its history across power-off knows at each switch-on: the
        // recording's activations in order (one unit per recording), with a clock that tells a
        // full cool-down; nothing is known of the time between recordings.
        for segment in &recording.segments {
            same_scale(&recording, segment, fitted)?;
        }
        let choose = |segment: &Segment| -> Option<(Split, &FittedUnit)> {
            let labels = &segment.labels;
            // The set point the activation belongs to: in a field session whose ambient
            // ramps, the switch-on label is the ambient of the moment (31.7, 35.2 … in a
            // +33 °C session), almost never a validation set point.
            let validation = is_one_of(
                labels.nominal_set_point_celsius(),
                &options.validation_set_points,
            );
            let (split, model) = if noise_floor {
                // The noise floor is measured where the other units are validated: every
                // activation of the twin's sessions at a validation set point.
                if !validation {
                    return None;
                }
                (Split::NoiseFloor, fitted)
            } else if labels.series_kind == SeriesKind::Field {
                (Split::Field, fitted)
            } else if validation {
                (Split::Validation, fitted)
            } else if calibration_segment(segment, options) {
                (
                    Split::HeldOutRepeat,
                    held_out.get(&(recording.unit_id.clone(), labels.repeat))?,
                )
            } else {
                return None;
            };
            Some((split, model))
        };
        let chosen: Vec<Option<(Split, &FittedUnit)>> =
            recording.segments.iter().map(choose).collect();
        let mut ambients = Vec::with_capacity(chosen.len());
        for (segment, chosen) in recording.segments.iter().zip(&chosen) {
            let channel = options
                .switch_on_ambient
                .as_deref()
                .filter(|_| chosen.is_some());
            ambients.push(switch_on_ambient(path, &recording, segment, channel)?);
        }
        let segments: Vec<&Segment> = recording.segments.iter().collect();
        let kept = kept_before(&segments, settings, &fitted.by_history.settings, true);
        let results: Vec<Evaluated> = recording
            .segments
            .par_iter()
            .zip(kept.par_iter())
            .zip(chosen.par_iter().zip(ambients.par_iter()))
            .filter_map(|((segment, previous), (chosen, &ambient))| {
                let (split, model) = (*chosen)?;
                let result = evaluate_at(model, segment, settings, previous, ambient);
                // σ(t) is fitted on the held-out repeats and checked on what no fit saw.
                let residual = (split != Split::NoiseFloor).then(|| {
                    uncertainty::residuals(&model.recommended, segment, settings, previous)
                });
                Some((split, result, residual))
            })
            .collect();
        for (split, result, residual) in results {
            outcome.results.push((split, result));
            if let Some(residual) = residual {
                residuals.push((split, residual));
            }
        }
    }
    progress.check(EVALUATE_STEP, total, total)?;
    // A validation set point asked for and never seen would vanish from the report silently
    // (field sessions at it count: they are validated too, in their own table).
    let validated = if noise_floor {
        Split::NoiseFloor
    } else {
        Split::Validation
    };
    if options.evaluate {
        if let Some(&set_point) = options.validation_set_points.iter().find(|s| {
            !outcome.results.iter().any(|(split, r)| {
                (*split == validated || *split == Split::Field)
                    && is_one_of(r.labels.nominal_set_point_celsius(), &[**s])
            })
        }) {
            return Err(PipelineError::MissingValidation {
                set_point,
                found: recorded_set_points,
                files: files.len(),
            });
        }
    }
    outcome.uncertainty = uncertainty::per_unit(&outcome.fitted, &residuals);
    let evaluate_seconds = started.elapsed().as_secs_f64();
    outcome.calibration = by_unit.into_values().flatten().collect();
    outcome.coverage =
        coverage::per_unit(&outcome.fitted, &outcome.calibration, &residuals, settings);
    outcome.timings = vec![
        ("read recordings (pass 1)".into(), read_seconds),
        ("analyse calibration activations".into(), analyse_seconds),
        (
            format!(
                "fit tables ({} unit{}, with refits per left-out repeat)",
                outcome.fitted.len(),
                if outcome.fitted.len() == 1 { "" } else { "s" }
            ),
            fit_seconds,
        ),
        (
            "read again, correct and evaluate (pass 2)".into(),
            evaluate_seconds,
        ),
    ];
    Ok(outcome)
}
