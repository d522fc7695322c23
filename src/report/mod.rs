//! `gyrodrift report`: the Markdown report and its figures, from fitted units and evaluation
//! results.

mod figures;
mod input;
pub mod measured;
pub mod plots;
pub mod tables;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use drift_evaluate::summary::{summarise, Record};
use drift_fit::FittedUnit;

use crate::output::write_atomic;
pub use input::ReportInput;

/// Writes `report.md`, `report.json` (the table as data) and the figures into `dir`; returns the
/// report's path.
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
    md.push_str(&tables::paper_table(&records, input.fitted));
    md.push_str(&tables::field_table(&records, input.fitted));
    md.push_str(&tables::noise_floor(&records, input.noise_floor_units));
    md.push_str(&tables::residual_rms(&records, input.fitted));
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
    if !input.timings.is_empty() {
        writeln!(
            md,
            "\n## Timings (this run)\n\n| step | seconds |\n|---|---:|"
        )?;
        for (step, seconds) in &input.timings {
            writeln!(md, "| {step} | {seconds:.2} |")?;
        }
    }
    let path = dir.join("report.md");
    write_atomic(&path, md.as_bytes())?;
    write_atomic(
        &dir.join("report.json"),
        serde_json::to_string_pretty(&records)?.as_bytes(),
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
