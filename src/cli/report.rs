//! `gyrodrift report`: fit, evaluate on data the fit did not see, and write the report.

use std::path::{Path, PathBuf};

use drift_fit::summary::Split;

use super::fit::{load_settings, write_tables};
use super::progress::Steps;
use crate::report::{write_report, ReportInput};
use drift_fit::pipeline::{self, Options, Outcome};

/// Options of `gyrodrift report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Campaign folder (with `recordings/`) or a folder of `.mcap` recordings.
    pub campaign: PathBuf,
    /// Chamber set points to fit, °C.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "30,40",
        allow_hyphen_values = true
    )]
    pub calibration: Vec<f64>,
    /// Chamber set points to validate on (never fitted), °C.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "33",
        allow_hyphen_values = true
    )]
    pub validation: Vec<f64>,
    /// Campaign folder of units with zero systematic drift: the noise floor.
    #[arg(long)]
    pub noise_floor: Option<PathBuf>,
    /// Output folder for the report, its figures and the fitted tables.
    #[arg(long, short = 'o', default_value = "out/report")]
    pub out: PathBuf,
    /// Fit settings as JSON.
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// Fits, evaluates and writes the report; returns the report's path and the main outcome.
pub fn make(
    campaign: &Path,
    noise_floor: Option<&Path>,
    options: &Options,
    out: &Path,
    provenance: Vec<String>,
    quiet: bool,
) -> anyhow::Result<(PathBuf, Outcome)> {
    let steps = Steps::new(quiet);
    let progress = |s: &str, d, t| steps.update(s, d, t);
    let files = pipeline::recording_files(campaign)?;
    let mut outcome = pipeline::run(&files, options, false, &progress)?;
    let mut noise_units = Vec::new();
    if let Some(dir) = noise_floor {
        let noise = pipeline::run(&pipeline::recording_files(dir)?, options, true, &progress)?;
        for (_, result) in &noise.results {
            let id = format!("noise:{}", result.labels.unit_id);
            if !noise_units.contains(&id) {
                noise_units.push(id);
            }
        }
        outcome
            .results
            .extend(noise.results.into_iter().map(|(split, mut r)| {
                r.labels.unit_id = format!("noise:{}", r.labels.unit_id);
                (split, r)
            }));
        outcome.timings.extend(
            noise
                .timings
                .into_iter()
                .map(|(step, s)| (format!("noise floor: {step}"), s)),
        );
    }
    steps.finish();
    write_tables(&out.join("tables"), &outcome.fitted)?;
    let input = ReportInput {
        title: "gyrodrift report: temperature-drift correction on data the fit did not see",
        provenance,
        fitted: &outcome.fitted,
        noise_floor_units: &noise_units,
        calibration: &outcome.calibration,
        results: &outcome.results,
        timings: outcome.timings.clone(),
    };
    let path = write_report(out, &input)?;
    Ok((path, outcome))
}

/// Prints the headline table of a finished report.
pub fn print_headline(outcome: &Outcome) {
    let records = drift_fit::summary::summarise(&outcome.results);
    print!(
        "{}",
        crate::report::headline_text(&records, &outcome.fitted, &noise_ids(outcome))
    );
}

fn noise_ids(outcome: &Outcome) -> Vec<String> {
    let mut ids: Vec<String> = outcome
        .results
        .iter()
        .filter(|(s, _)| *s == Split::NoiseFloor)
        .map(|(_, r)| r.labels.unit_id.clone())
        .collect();
    ids.sort();
    ids.dedup();
    ids
}

/// Runs `gyrodrift report`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let options = Options {
        calibration_set_points: args.calibration.clone(),
        validation_set_points: args.validation.clone(),
        fit: load_settings(args.settings.as_deref())?,
        held_out_repeats: true,
        evaluate: true,
    };
    let provenance = vec![format!(
        "Recordings: `{}`; calibration {:?} °C, validation {:?} °C.",
        args.campaign.display(),
        args.calibration,
        args.validation
    )];
    let (path, outcome) = make(
        &args.campaign,
        args.noise_floor.as_deref(),
        &options,
        &args.out,
        provenance,
        args.quiet,
    )?;
    print_headline(&outcome);
    println!("report: {}", path.display());
    Ok(())
}
