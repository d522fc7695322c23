//! `gyrodrift check`: is a unit's stored calibration still valid? Its firmware image, run over new
//! recordings of the unit held static, against the bench's limits.

use std::collections::btree_map::Entry;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use drift_core::blob::Image;
use drift_core::{
    Model, ModifiedTables, PolynomialTables, RecommendedTables, RelativePolynomialTables,
};
use drift_evaluate::check::{AxisVerdict, CheckedActivation, Limits, UnitCheck};
use drift_evaluate::pipeline;
use drift_evaluate::tables_folder::{self, StoredModel, TablesError};
use drift_fit::FitSettings;
use drift_recording::output_folder::{Owned, Writer};
use drift_recording::read_recording;

use super::campaign_args::load_settings;
use super::exit::LimitsMissed;
use super::progress::Steps;
use drift_report::write_atomic;

/// Which of a unit's stored models to check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Stored {
    /// The recommended model (`recommended.bin`, the default: the image to deploy): the paper's
    /// drift correction with the turn-on bias fitted on every calibration activation; each unit's
    /// activations run in recording order, each starting from what its firmware kept of the one
    /// before.
    Recommended,
    /// The paper's tables (`modified.bin`).
    Modified,
    /// The paper's curves with stage 3 keyed by heating history (`by_history.bin`); each unit's
    /// activations run in recording order, each starting from what its firmware kept of the one
    /// before.
    ByHistory,
    /// The paper's standard polynomial (`standard.bin`).
    Standard,
    /// The 3rd-order polynomial (`third_order.bin`).
    ThirdOrder,
    /// The least-squares polynomial relative to the switch-on (`relative.bin`).
    Relative,
}

impl Stored {
    /// The tables folder's model.
    pub fn model(self) -> StoredModel {
        match self {
            Self::Modified => StoredModel::Modified,
            Self::ByHistory => StoredModel::ByHistory,
            Self::Standard => StoredModel::Standard,
            Self::ThirdOrder => StoredModel::ThirdOrder,
            Self::Relative => StoredModel::Relative,
            Self::Recommended => StoredModel::Recommended,
        }
    }
}

/// Options of `gyrodrift check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Campaign folder (with `recordings/`) or a folder of `.mcap` recordings of the units, held
    /// static (every activation is checked, whatever its labels).
    pub recordings: PathBuf,
    /// Folder of fitted tables, one subfolder per unit (what `gyrodrift fit` writes); the firmware
    /// image `<tables>/<unit>/<model>.bin` is what is checked.
    #[arg(long)]
    pub tables: PathBuf,
    /// Which stored model the units run (the recommended one unless told).
    #[arg(long, value_enum, default_value = "recommended")]
    pub model: Stored,
    /// Most drift left per activation (mean over activations, per axis), °/s.
    #[arg(long, default_value_t = Limits::default().max_drift_dps, allow_negative_numbers = true)]
    pub max_drift: f64,
    /// Largest residual bias RMS (per axis), °/s.
    #[arg(long, default_value_t = Limits::default().max_residual_rms_dps, allow_negative_numbers = true)]
    pub max_rms: f64,
    /// Smallest share (0…1) of the uncorrected drift the tables must remove.
    #[arg(long, default_value_t = Limits::default().min_removed, allow_negative_numbers = true)]
    pub min_removed: f64,
    /// Fit settings as JSON (the switch-on window and the low-pass the fit used).
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// Output folder for `check.md` and `check.json`.
    #[arg(long, short = 'o', default_value = "out/check")]
    pub out: PathBuf,
    /// Replace an earlier `gyrodrift check` output in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// No progress bars.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// `check` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "check",
    product: "check report",
    doing: "checking",
    owned: Owned::Marker,
};

/// One unit's result.
#[derive(Debug, serde::Serialize)]
struct UnitResult {
    unit_id: String,
    image: PathBuf,
    axes: [AxisVerdict; 3],
    activations: Vec<CheckedActivation>,
}

/// The image `unit` carries, decoded; errors name the file. An image whose header names another
/// unit is refused, naming both: a unit checked (or flashed) with another's tables fails for the
/// wrong reason. An image that names no unit (written without one) is taken as the unit's.
fn load<M: Image>(path: &Path, unit: &str, recording: &Path) -> anyhow::Result<M> {
    let (model, header) =
        tables_folder::read_image_and_header(path).map_err(|error| match error {
            TablesError::Io { .. } => {
                anyhow::anyhow!(
                    "{error} (no stored tables for this unit? `gyrodrift fit` writes them)"
                )
            }
            other => other.into(),
        })?;
    let owner = header.provenance.unit_id.as_str();
    if !owner.is_empty() && owner != unit {
        bail!(
            "{}: this image is unit {owner}'s, but {} records unit {unit}: each unit is checked with its own image (`<tables>/{unit}/`)",
            path.display(),
            recording.display()
        );
    }
    Ok(model)
}

/// Checks every activation of every recording against the unit's stored `M`.
fn check_all<M: Model + Image>(
    args: &Args,
    files: &[PathBuf],
    settings: &FitSettings,
    limits: &Limits,
    steps: &Steps,
) -> anyhow::Result<Vec<UnitResult>> {
    let mut units: BTreeMap<String, (PathBuf, UnitCheck<M>)> = BTreeMap::new();
    for (i, path) in files.iter().enumerate() {
        steps.update(
            "correcting with the stored tables",
            i as u64,
            files.len() as u64,
        );
        let recording = read_recording(path)?;
        let unit = &recording.unit_id;
        let (_, check) = match units.entry(unit.clone()) {
            Entry::Occupied(entry) => entry.into_mut(),
            Entry::Vacant(entry) => {
                let image = args.model.model().image_path(&args.tables, unit);
                let model: M = load(&image, unit, path)?;
                let check = UnitCheck::new(unit, model, settings)
                    .with_context(|| image.display().to_string())?;
                entry.insert((image, check))
            }
        };
        // A recording's activations in order, each starting from what the firmware kept of the
        // one before; nothing is known of the time between recordings.
        check.forget_history();
        for segment in &recording.segments {
            check.add(segment);
        }
    }
    Ok(units
        .into_iter()
        .map(|(unit_id, (image, check))| UnitResult {
            axes: check.verdicts(limits),
            activations: check.into_activations(),
            unit_id,
            image,
        })
        .collect())
}

/// The axis names, by axis index.
const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The verdicts as a Markdown table (printed, and the heart of `check.md`).
fn table(results: &[UnitResult]) -> String {
    let mut md = String::from(
        "| unit | axis | activations | uncorrected drift | drift left | worst | removed | residual RMS | ambient out of range | rise out of span | past last reference | history unknown or out of span | faults | verdict |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for unit in results {
        for v in &unit.axes {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.0} % | {:.4} | {} | {} | {} | {} | {} | {} |",
                unit.unit_id,
                AXES[v.axis],
                v.activations,
                v.uncorrected_drift_dps,
                v.corrected_drift_dps,
                v.worst_drift_dps,
                100.0 * v.removed,
                v.residual_rms_dps,
                v.ambient_out_of_range,
                v.rise_out_of_span,
                v.past_last_reference,
                v.history_unknown_or_out_of_span,
                v.faulty,
                if v.passed() {
                    "pass".to_owned()
                } else {
                    format!("**fail**: {}", v.failures.join("; "))
                }
            );
        }
    }
    md
}

/// Per unit, the share of the checked data outside the calibrated envelope (switch-on
/// temperature or residual heat beyond the calibration's, as the corrector flags it), over
/// activations × axes and over samples: there the check measures the envelope as much as the
/// tables.
fn outside_envelope(results: &[UnitResult]) -> String {
    let mut out = String::new();
    for unit in results {
        let (mut pairs, mut pairs_out, mut samples, mut samples_out) = (0, 0, 0, 0);
        for v in &unit.axes {
            pairs += v.activations;
            pairs_out += v.outside_envelope;
            samples += v.samples;
            samples_out += v.outside_envelope_samples;
        }
        let share = |part: usize, whole: usize| {
            if whole == 0 {
                "–".to_owned()
            } else {
                format!("{:.1} %", 100.0 * part as f64 / whole as f64)
            }
        };
        let _ = writeln!(
            out,
            "{}: outside the calibrated envelope: {} of activations × axes ({pairs_out} of {pairs}), {} of samples",
            unit.unit_id,
            share(pairs_out, pairs),
            share(samples_out, samples)
        );
    }
    out
}

/// `check.md`: what was checked against which limits, the table, what its columns mean.
fn markdown(results: &[UnitResult], limits: &Limits) -> String {
    let mut md = format!(
        "# Calibration check\n\nThe stored firmware image of each unit, run through drift-core's corrector over every activation recorded (unit static), against the limits: drift left ≤ {} °/s, residual RMS ≤ {} °/s, removed ≥ {:.0} %. Drift: max − min of the 1-s low-passed rate per activation, mean over activations; residual RMS: RMS of the 1-s low-passed corrected rate (includes the switch-on bias the tables predict).\n\n",
        limits.max_drift_dps,
        limits.max_residual_rms_dps,
        100.0 * limits.min_removed
    );
    md.push_str(&table(results));
    md.push_str("\nThe flag columns count activations: switched on outside the calibrated ambients, rise outside the stored curves (both clamped), running past the last reference time (`k` held), as the corrector documents; \"faults\" counts activations with a sensor or table fault flag. An activation outside the envelope measures the envelope as much as the tables.\n\n");
    md.push_str(&outside_envelope(results));
    md
}

/// What a check on the tables' own calibration recordings means, if any of `files` is one.
fn in_sample_note(in_sample: &[(PathBuf, String)], files: usize) -> Option<String> {
    let (first, name) = in_sample.first()?;
    Some(format!(
        "{} of {files} recordings checked are calibration data these tables were fitted on ({} is {name}): on them the check measures how well the tables fit their own data, not whether the calibration still holds; check on recordings made after the calibration",
        in_sample.len(),
        first.display()
    ))
}

/// Runs `gyrodrift check`; fails with `LimitsMissed` (exit status 1) when any unit × axis
/// misses a limit, after writing the report; any other error (no tables, unreadable recordings,
/// bad limits) exits with status 2.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let limits = Limits {
        max_drift_dps: args.max_drift,
        max_residual_rms_dps: args.max_rms,
        min_removed: args.min_removed,
    };
    if let Some((field, value)) = limits.invalid() {
        let flag = match field {
            "max_drift_dps" => "--max-drift",
            "max_residual_rms_dps" => "--max-rms",
            _ => "--min-removed",
        };
        bail!("{flag} must be {}, got {value}", Limits::requirement(field));
    }
    let files = pipeline::recording_files(&args.recordings)?;
    let settings = load_settings(args.settings.as_deref())?;
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let steps = Steps::new(args.quiet);
    let results = match args.model {
        Stored::Modified | Stored::ByHistory => {
            check_all::<ModifiedTables>(args, &files, &settings, &limits, &steps)?
        }
        Stored::Standard | Stored::ThirdOrder => {
            check_all::<PolynomialTables>(args, &files, &settings, &limits, &steps)?
        }
        Stored::Relative => {
            check_all::<RelativePolynomialTables>(args, &files, &settings, &limits, &steps)?
        }
        Stored::Recommended => {
            check_all::<RecommendedTables>(args, &files, &settings, &limits, &steps)?
        }
    };
    steps.finish();
    let in_sample = super::in_sample::shared(&args.tables, &files)?;
    let mut md = markdown(&results, &limits);
    let note = in_sample_note(&in_sample, files.len());
    if let Some(note) = &note {
        md.push_str(&format!("\n**In-sample.** {note}\n"));
    }
    let json = serde_json::to_string_pretty(&serde_json::json!({
        "limits": limits,
        "units": results,
        "in_sample_recordings": in_sample.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
    }))?;
    write_atomic(&staged.path().join("check.json"), json.as_bytes())?;
    write_atomic(&staged.path().join("check.md"), md.as_bytes())?;
    staged.commit()?;
    print!("{}", table(&results));
    print!("{}", outside_envelope(&results));
    if let Some(note) = &note {
        println!("in-sample: {note}");
    }
    println!("report: {}", args.out.join("check.md").display());
    let failed: Vec<String> = results
        .iter()
        .flat_map(|u| {
            u.axes
                .iter()
                .filter(|v| !v.passed())
                .map(move |v| format!("{} {}", u.unit_id, AXES[v.axis]))
        })
        .collect();
    if !failed.is_empty() {
        return Err(LimitsMissed(format!(
            "the calibration misses the limits on {} of {} unit × axis: {}",
            failed.len(),
            3 * results.len(),
            failed.join(", ")
        ))
        .into());
    }
    Ok(())
}
