//! The report, the data flow's last step: recordings → fitted tables → evaluation on what the fit
//! did not see → `report.md` (tables and SVG figures), `report.json` (the table as data) and the
//! tables folder. `gyrodrift report`, `gyrodrift demo` and Python's `gyrodrift.report` all make it
//! through [`make`], so the same inputs give the same bytes.

mod at_ambient;
mod coverage;
pub mod diagnosis;
mod evaluation_units;
mod figures;
mod input;
pub mod measured;
pub mod plots;
pub mod tables;
mod uncertainty;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_evaluate::pipeline::{self, Options, Outcome, Progress};
use drift_evaluate::summary::{absolute_error, summarise, Record, Split};
use drift_evaluate::tables_folder;
use drift_fit::FittedUnit;

pub use input::ReportInput;

/// Writes `bytes` to `path` whole or not at all ([`drift_recording::write_atomic`]), creating its
/// folder if missing; the error names the file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    drift_recording::write_atomic_creating_folder(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}

/// The report's title line.
pub const TITLE: &str =
    "gyrodrift report: temperature-drift correction on data the fit did not see";

/// Fits on `files`, evaluates on everything the fits did not see (and the noise-floor twin's
/// `noise_floor` files, if given), writes the tables folder `<out>/tables/` and the report into
/// `out`; returns the report's path and the outcome. `provenance` is Markdown lines saying how the
/// data and the report were made.
pub fn make(
    files: &[PathBuf],
    noise_floor: Option<&[PathBuf]>,
    options: &Options,
    out: &Path,
    provenance: Vec<String>,
    progress: Progress<'_>,
) -> anyhow::Result<(PathBuf, Outcome)> {
    let (outcome, noise_units) =
        pipeline::run_with_noise_floor(files, noise_floor, options, progress)?;
    write_outcome(outcome, &noise_units, options, out, provenance)
}

/// [`make`] with the data split by source: fits on the calibration activations of `calibration`
/// and judges on every activation of `evaluation` ([`pipeline::run_separate`]). Also returns
/// warnings, each on top of the report too: evaluation recordings whose uncorrected drift is
/// tens of times the calibration's (another rate unit).
pub fn make_separate(
    calibration: &[PathBuf],
    evaluation: &[PathBuf],
    noise_floor: Option<&[PathBuf]>,
    options: &Options,
    out: &Path,
    mut provenance: Vec<String>,
    progress: Progress<'_>,
) -> anyhow::Result<(PathBuf, Outcome, Vec<String>)> {
    let (outcome, noise_units) =
        pipeline::run_separate(calibration, evaluation, noise_floor, options, progress)?;
    let warnings = evaluation_units::warnings(&outcome, evaluation);
    for warning in &warnings {
        provenance.push(format!("\n**Warning:** {warning}."));
    }
    let (path, outcome) = write_outcome(outcome, &noise_units, options, out, provenance)?;
    Ok((path, outcome, warnings))
}

fn write_outcome(
    outcome: Outcome,
    noise_units: &[String],
    options: &Options,
    out: &Path,
    provenance: Vec<String>,
) -> anyhow::Result<(PathBuf, Outcome)> {
    tables_folder::write(&out.join("tables"), &outcome.fitted)?;
    tables_folder::write_uncertainty(&out.join("tables"), &outcome.uncertainty)?;
    let input = ReportInput {
        title: TITLE,
        provenance,
        fitted: &outcome.fitted,
        noise_floor_units: noise_units,
        calibration: &outcome.calibration,
        results: &outcome.results,
        independent_after_min: options.fit.independent_after_min,
        timings: outcome.timings.clone(),
        uncertainty: &outcome.uncertainty,
        coverage: &outcome.coverage,
        switch_on_ambient: options.switch_on_ambient.as_deref(),
    };
    let path = write_report(out, &input)?;
    Ok((path, outcome))
}

/// How the report's data were chosen, as its provenance line: the recordings as `source` names
/// them, the calibration and validation set points.
pub fn provenance(source: &str, options: &Options) -> Vec<String> {
    let mut lines = vec![format!(
        "Recordings: `{source}`; calibration {:?} °C, validation {:?} °C.",
        options.calibration_set_points, options.validation_set_points
    )];
    lines.extend(ambient_provenance(options));
    lines
}

/// The provenance line of a switch-on ambient read from a logged channel, if one was named.
pub fn ambient_provenance(options: &Options) -> Option<String> {
    options.switch_on_ambient.as_ref().map(|channel| {
        format!(
            "Switch-on ambient: the `{channel}` channel at each activation's switch-on; the paper's tables are also evaluated started there (*modified-at-ambient*)."
        )
    })
}

/// What a finished report says first, for printing: the headline table (Markdown), the
/// absolute-error verdict and the field-like results' means, as `report.md` has them.
/// `independent_after_min` is the fit's cool-down (what counts as a cold start).
pub fn headline_of(outcome: &Outcome, independent_after_min: f64) -> String {
    let records = summarise(&outcome.results);
    let mut noise: Vec<String> = outcome
        .results
        .iter()
        .filter(|(split, _)| *split == Split::NoiseFloor)
        .map(|(_, r)| r.labels.unit_id.clone())
        .collect();
    noise.sort();
    noise.dedup();
    let mut text = tables::headline(&records, &outcome.fitted, &noise);
    let cells = absolute_error(&outcome.results, independent_after_min);
    if !cells.is_empty() {
        let _ = writeln!(
            text,
            "{} (report.md: *Absolute error*).",
            tables::absolute_error_verdict(&cells)
        );
    }
    if let Some(field) = tables::field_headline(&records, &outcome.fitted) {
        let _ = writeln!(text, "{field} (report.md: *Field-like use*).");
    }
    text
}

/// Writes `report.md`, `report.json` (the table as data), `uncertainty.json` (σ(t) and its
/// coverage, when fitted), `coverage.json` (the calibration's coverage map), the figures and `timings.json` (how
/// long each step took) into `dir`; returns the report's path.
pub fn write_report(dir: &Path, input: &ReportInput<'_>) -> anyhow::Result<PathBuf> {
    let records = summarise(input.results);
    let figures = figures::write_all(dir, input)?;
    let mut md = String::new();
    writeln!(md, "# {}\n", input.title)?;
    for line in &input.provenance {
        writeln!(md, "{line}")?;
    }
    writeln!(md)?;
    md.push_str(&tables::headline(
        &records,
        input.fitted,
        input.noise_floor_units,
    ));
    let cells = absolute_error(input.results, input.independent_after_min);
    md.push_str(&tables::absolute_error_flags(&cells));
    md.push_str(&tables::absolute_error_by_class(&cells));
    md.push_str(&tables::paper_table(&records, input.fitted));
    md.push_str(&tables::field_table(&records, input.fitted));
    md.push_str(&tables::noise_floor(&records, input.noise_floor_units));
    md.push_str(&tables::residual_rms(&records, input.fitted));
    md.push_str(&at_ambient::section(
        &records,
        input.switch_on_ambient,
        input.noise_floor_units,
    ));
    md.push_str(&tables::absolute_error(&cells));
    md.push_str(&uncertainty::section(input.uncertainty));
    md.push_str(&coverage::section(dir, input.coverage)?);
    if !figures.is_empty() {
        writeln!(md, "## Figures\n")?;
        for (file, caption) in &figures {
            writeln!(md, "![{caption}]({file})\n\n*{caption}*\n")?;
        }
    }
    writeln!(md, "## Fit\n")?;
    for unit in input.fitted {
        let refs: Vec<String> = unit.modified.axes[0]
            .reference_ms
            .iter()
            .map(|ms| format!("{}", f64::from(*ms) / 1000.0))
            .collect();
        writeln!(
            md,
            "- {}: {} curves per ambient ({}), {} calibration ambients, reference times (X) {} s",
            unit.unit_id,
            unit.curve_keys.len(),
            unit.curve_keys
                .iter()
                .map(|k| k.name())
                .collect::<Vec<_>>()
                .join(", "),
            unit.modified.axes[0].ambients.len(),
            refs.join(", ")
        )?;
        for note in &unit.notes {
            writeln!(md, "  - {note}")?;
        }
    }
    let path = dir.join("report.md");
    write_atomic(&path, md.as_bytes())?;
    write_atomic(
        &dir.join("report.json"),
        serde_json::to_string_pretty(&records)?.as_bytes(),
    )?;
    write_atomic(
        &dir.join("absolute_error.json"),
        serde_json::to_string_pretty(&cells)?.as_bytes(),
    )?;
    if !input.uncertainty.is_empty() {
        write_atomic(
            &dir.join("uncertainty.json"),
            serde_json::to_string_pretty(input.uncertainty)?.as_bytes(),
        )?;
    }
    if !input.coverage.is_empty() {
        write_atomic(
            &dir.join("coverage.json"),
            serde_json::to_string_pretty(input.coverage)?.as_bytes(),
        )?;
    }
    // Durations differ from run to run; kept apart so the report itself is the same bytes for
    // the same inputs.
    let timings: Vec<serde_json::Value> = input
        .timings
        .iter()
        .map(|(step, seconds)| serde_json::json!({ "step": step, "seconds": seconds }))
        .collect();
    write_atomic(
        &dir.join("timings.json"),
        serde_json::to_string_pretty(&timings)?.as_bytes(),
    )?;
    Ok(path)
}

/// The headline table (Markdown), for printing.
pub fn headline_text(
    records: &[Record],
    fitted: &[FittedUnit],
    noise_floor_units: &[String],
) -> String {
    tables::headline(records, fitted, noise_floor_units)
}
