//! `gyrodrift report`: fit, evaluate on data the fit did not see, and write the report.

use std::path::{Path, PathBuf};

use super::campaign_args::CampaignArgs;
use super::measured;
use super::progress::Steps;
use super::shared_data::refuse_shared;
use drift_evaluate::pipeline::PipelineError;
use drift_evaluate::pipeline::{self, Options, Outcome};
use drift_recording::output_folder::{Owned, Writer};
use drift_recording::paper;
use drift_report::measured::write_measured_report;

/// Options of `gyrodrift report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Recordings and fit settings.
    #[command(flatten)]
    pub input: CampaignArgs,
    /// Chamber set points to validate on (never fitted), °C.
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = [paper::VALIDATION_SET_POINT_CELSIUS],
        allow_hyphen_values = true
    )]
    pub validation: Vec<f64>,
    /// Recordings to judge on, a source separate from the calibration data (the campaign or
    /// `--calibration-data`): every activation of the fitted units, none of which reaches a fit
    /// (protocol activations as validation at their set point, field sessions as field);
    /// `--validation` is not used.
    #[arg(long, value_name = "DIR")]
    pub evaluation_data: Option<PathBuf>,
    /// Campaign folder of units with zero systematic drift: the noise floor, measured at the
    /// validation set points (with `--evaluation-data`: at the evaluation data's). A twin with no
    /// calibration activations of its own is corrected with the tables of the unit of its id.
    #[arg(long)]
    pub noise_floor: Option<PathBuf>,
    /// Output folder for the report, its figures and the fitted tables.
    #[arg(long, short = 'o', default_value = "out/report")]
    pub out: PathBuf,
    /// Replace an earlier `gyrodrift report` output in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// A logged channel that holds the ambient the instrument measured (`chamber_air`, or
    /// `chamber_set_point`, which a field recording logs as the ambient it went through): the
    /// paper's tables are also evaluated with stage 2 and the initial bias read at its value at
    /// each activation's switch-on (`modified-at-ambient`, drift-core's `power_on_at_ambient`).
    /// Every evaluated activation must log it.
    #[arg(long, value_name = "CHANNEL")]
    pub switch_on_ambient: Option<String>,
}

/// `report` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "report",
    product: "report",
    doing: "reporting",
    owned: Owned::Marker,
};

/// Fits, evaluates and writes the report ([`drift_report::make`]) with progress bars; returns the
/// report's path and the main outcome.
pub fn make(
    campaign: &Path,
    noise_floor: Option<&Path>,
    options: &Options,
    out: &Path,
    provenance: Vec<String>,
    quiet: bool,
) -> anyhow::Result<(PathBuf, Outcome)> {
    let steps = Steps::new(quiet);
    let files = pipeline::recording_files(campaign)?;
    let noise_files = noise_floor.map(pipeline::recording_files).transpose()?;
    if let Some(noise) = &noise_files {
        refuse_shared(
            ("the campaign", &files),
            ("--noise-floor", noise),
            NOISE_FLOOR_APART,
        )?;
    }
    let made = drift_report::make(
        &files,
        noise_files.as_deref(),
        options,
        out,
        provenance,
        &steps,
    );
    steps.finish();
    let made = made?;
    super::in_sample::write(&out.join("tables"), &files, options)?;
    Ok(made)
}

/// Why a noise floor must be other recordings than the data it is set beside.
const NOISE_FLOOR_APART: &str = "the noise floor is a zero-drift twin recorded like the data \
     (`gyrodrift simulate --zero-drift`, or a unit without a temperature effect), never the data \
     itself; give such a campaign as --noise-floor, or leave the flag out";

/// Where `path`, written into a staging folder, is once the folder is in place as `out`.
pub fn in_target(out: &Path, path: &Path) -> PathBuf {
    path.file_name()
        .map_or_else(|| out.to_owned(), |name| out.join(name))
}

/// Prints the headline table of a finished report, its absolute-error verdict and its field-like
/// results.
pub fn print_headline(outcome: &Outcome, options: &Options) {
    print!("{}", headline(outcome, options));
}

/// The headline [`print_headline`] prints.
pub fn headline(outcome: &Outcome, options: &Options) -> String {
    drift_report::headline_of(outcome, options.fit.independent_after_min)
}

/// Runs `gyrodrift report`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let input = &args.input;
    let mut options = input.options(&args.validation, true)?;
    options
        .switch_on_ambient
        .clone_from(&args.switch_on_ambient);
    if let Some(evaluation) = &args.evaluation_data {
        return run_separate(args, evaluation, &options);
    }
    let provenance = drift_report::provenance(&input.source().display().to_string(), &options);
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let made = make(
        input.source(),
        args.noise_floor.as_deref(),
        &options,
        staged.path(),
        provenance.clone(),
        input.quiet,
    );
    let error = match made {
        Ok((path, outcome)) => {
            staged.commit()?;
            print_headline(&outcome, &options);
            println!("report: {}", in_target(&args.out, &path).display());
            return Ok(());
        }
        Err(error) => error,
    };
    // Data the paper's method cannot be fitted on: say why, and report what it does tell.
    if !error
        .downcast_ref::<PipelineError>()
        .is_some_and(measured::may_be_unfittable)
    {
        return Err(error);
    }
    let files = pipeline::recording_files(input.source())?;
    let unfittable = measured::unfittable(&files)?;
    if unfittable.is_empty() {
        return Err(error);
    }
    for unit in &unfittable {
        println!("{unit}");
    }
    let units = measured::characterise_files(&files)?;
    let path = write_measured_report(staged.path(), &units, &provenance, &error.to_string())?;
    staged.commit()?;
    let path = in_target(&args.out, &path);
    for c in &units {
        for axis in &c.axes {
            let correction = axis.correction.map_or(String::new(), |r| {
                format!(
                    "; residual RMS {:.5} → {:.5} °/s after a linear temperature correction (leave one activation out)",
                    r.rms_before_dps, r.rms_after_dps
                )
            });
            println!(
                "{} {}: temperature slope {} (°/s)/°C{correction}",
                c.unit_id,
                axis.axis,
                axis.within_slope.map_or("–".into(), |e| format!(
                    "{:+.4} ± {:.4}",
                    e.value, e.standard_error
                ))
            );
        }
    }
    println!(
        "report (measured data, no tables fitted): {}",
        path.display()
    );
    Ok(())
}

/// `gyrodrift report --calibration-data A --evaluation-data B`: fit on A, judge on B.
fn run_separate(args: &Args, evaluation: &Path, options: &Options) -> anyhow::Result<()> {
    let input = &args.input;
    let mut provenance = vec![format!(
        "Calibration data: `{}` (calibration {:?} °C); evaluation data: `{}` (every activation of the fitted units; none reaches a fit).",
        input.source().display(),
        options.calibration_set_points,
        evaluation.display()
    )];
    provenance.extend(drift_report::ambient_provenance(options));
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let steps = Steps::new(input.quiet);
    let calibration = pipeline::recording_files(input.source())?;
    let evaluated = pipeline::recording_files(evaluation)?;
    let noise_files = args
        .noise_floor
        .as_deref()
        .map(pipeline::recording_files)
        .transpose()?;
    refuse_shared(
        ("--calibration-data", &calibration),
        ("--evaluation-data", &evaluated),
        "the evaluation data must be recordings the fit does not see; give other recordings of the \
         fitted units as --evaluation-data",
    )?;
    if let Some(noise) = &noise_files {
        for (flag, files) in [
            ("--calibration-data", &calibration),
            ("--evaluation-data", &evaluated),
        ] {
            refuse_shared((flag, files), ("--noise-floor", noise), NOISE_FLOOR_APART)?;
        }
    }
    let made = drift_report::make_separate(
        &calibration,
        &evaluated,
        noise_files.as_deref(),
        options,
        staged.path(),
        provenance,
        &steps,
    );
    steps.finish();
    let (path, outcome, warnings) = made?;
    super::in_sample::write(&staged.path().join("tables"), &calibration, options)?;
    staged.commit()?;
    for warning in &warnings {
        eprintln!("warning: {warning}");
    }
    print_headline(&outcome, options);
    println!("report: {}", in_target(&args.out, &path).display());
    Ok(())
}
