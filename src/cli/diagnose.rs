//! `gyrodrift diagnose`: which quantity explains what the paper's model leaves in the residual?

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use drift_diagnose::activations::{loop_settings, read_by_unit, DIAGNOSIS_RATE_HZ};
use drift_diagnose::closing::{close_both, close_separate_both, Closed, LoopOptions};
use drift_evaluate::pipeline;
use drift_fit::FittedUnit;
use drift_recording::output_folder::{Owned, Writer};
use drift_recording::{Segment, Within};
use drift_report::diagnosis::{self, Request};

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use super::shared_data::refuse_shared;

/// Options of `gyrodrift diagnose`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Recordings and fit settings.
    #[command(flatten)]
    pub input: CampaignArgs,
    /// Output folder for `diagnosis.md` and `diagnosis.json`.
    #[arg(long, short = 'o', default_value = "out/diagnosis")]
    pub out: PathBuf,
    /// Replace an earlier `gyrodrift diagnose` output in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// How many candidates to print per axis.
    #[arg(long, default_value_t = 5)]
    pub top: usize,
    /// Close the loop: offer the significant winners as the extended model's terms, admit each
    /// only where it lowers the error on held-out field-like activations at the calibration set
    /// points, fit their coefficients there, refit the tables, and report the error before and
    /// after on the activations held out (other set points and sessions).
    #[arg(long)]
    pub extend: bool,
    /// Campaign folder of units with zero systematic drift recorded like this one
    /// (`gyrodrift simulate --zero-drift`): the noise floor, per set point, beside the error before
    /// and after.
    #[arg(long, requires = "extend")]
    pub noise_floor: Option<PathBuf>,
    /// Set points (not the calibration's) whose protocol activations the diagnosis also ranks
    /// candidates on, e.g. the validation campaign: more activations to find an effect with, and
    /// none of them measured on afterwards (the before/after uses the rest).
    #[arg(long, value_delimiter = ',', value_name = "CELSIUS,...")]
    pub select_on: Vec<f64>,
    /// Set points whose series — field and protocol — are the diagnosis data, e.g. a field
    /// campaign recorded at +33 °C for the purpose. Cross-fitted by series: the loop ranks, fits and
    /// guards on half of the series and is judged on the other half, then the halves swap; the
    /// report shows both halves and whether they agree.
    #[arg(long, value_delimiter = ',', value_name = "CELSIUS,...")]
    pub diagnose_on: Vec<f64>,
    /// Recordings whose activations (of the fitted units, at any set point) are the diagnosis
    /// data, cross-fitted by series like `--diagnose-on`.
    #[arg(long, value_name = "DIR")]
    pub diagnosis_data: Option<PathBuf>,
    /// A recorded channel that describes the bench, not the unit (repeatable): context for the
    /// report, never ranked and never a firmware term. The chamber's set point and air
    /// (`chamber_set_point`, `chamber_air`) always are.
    #[arg(long = "bench-channel", value_name = "NAME")]
    pub bench_channels: Vec<String>,
    /// Recordings to judge on, a source separate from the calibration data (the campaign or
    /// `--calibration-data`), as `report --evaluation-data` does: every activation of the fitted
    /// units there is held out (the error before and after, the profiles), and none reaches the
    /// tables, a choice, the ranking or the extended model, which all come from the calibration
    /// data. The calibration data's own activations outside the calibration and training roles (and
    /// `--select-on`) are not judged on; the ranking uses them when there are no training
    /// activations (and only with neither does it rank on the evaluation data, as `diagnose`
    /// alone ranks on the held-out ones). Units without activations there are left out.
    #[arg(long, value_name = "DIR")]
    pub evaluation_data: Option<PathBuf>,
}

/// One day, ns: how far after the calibration data's last activation the evaluation data's life
/// starts on the clock (activations are known by their switch-on time, and two sources may share a
/// clock origin).
const DAY_NS: u64 = 86_400_000_000_000;

/// The evaluation data's activations per unit (only the units in `fitted`), each unit's moved on the
/// clock to a day after that unit's last activation in `source` (their order and off-times kept).
fn evaluation_segments(
    dir: &std::path::Path,
    source: &BTreeMap<String, Vec<Segment>>,
    fitted: &[FittedUnit],
) -> anyhow::Result<BTreeMap<String, Vec<Segment>>> {
    let files = pipeline::recording_files(dir)?;
    let mut units = read_by_unit(&files, drift_recording::QUIET)?;
    let seen: Vec<String> = units.keys().cloned().collect();
    units.retain(|unit, _| fitted.iter().any(|f| &f.unit_id == unit));
    anyhow::ensure!(
        !units.is_empty(),
        "{}: the evaluation data's units ({}) are none of the units fitted on the calibration data ({}): give recordings of the same units",
        dir.display(),
        seen.join(", "),
        fitted.iter().map(|f| f.unit_id.as_str()).collect::<Vec<_>>().join(", ")
    );
    for (unit, segments) in &mut units {
        let end = source
            .get(unit)
            .into_iter()
            .flatten()
            .map(|s| {
                let period = 1_000_000_000 / u64::from(s.sample_rate_hz.max(1));
                s.power_on_ns + s.len() as u64 * period
            })
            .max()
            .unwrap_or(0);
        let first = segments.iter().map(|s| s.power_on_ns).min().unwrap_or(0);
        let start = end.saturating_add(DAY_NS);
        for s in segments.iter_mut() {
            s.power_on_ns = s
                .power_on_ns
                .checked_sub(first)
                .and_then(|t| t.checked_add(start))
                .ok_or_else(|| {
                    anyhow::anyhow!("unit {unit}: the evaluation data's clock overflows")
                })?;
        }
    }
    Ok(units)
}

/// `diagnose` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "diagnose",
    product: "diagnosis",
    doing: "diagnosing",
    owned: Owned::Marker,
};

/// Runs `gyrodrift diagnose`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let input = &args.input;
    let mut options = input.options(&[], false)?;
    // The loop works on 0.1-s block means: its analysis grid is a whole number of them.
    options.fit = loop_settings(&options.fit);
    if let Some(shared) = args
        .diagnose_on
        .iter()
        .find(|t| pipeline::is_one_of(**t, &options.calibration_set_points))
    {
        anyhow::bail!(
            "--diagnose-on {shared}: a calibration set point ({:?} °C); its protocol is the tables' and its field activations already rank as training. Name set points the calibration does not use, or give the data with --diagnosis-data",
            options.calibration_set_points
        );
    }
    // Everything is written into a staging folder put in place at the end: a failed or
    // interrupted diagnosis leaves an earlier one as it was, and no stale file of it survives.
    let files = pipeline::recording_files(input.source())?;
    refuse_shared_inputs(&files, args)?;
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let out = staged.path().to_path_buf();
    let steps = Steps::new(input.quiet);
    // The tables are fitted on the activations as the loop sees them: at its rate.
    let outcome = pipeline::fit_at_rate(&files, &options, DIAGNOSIS_RATE_HZ, &steps)
        .map_err(|e| super::measured::explain(e, &files))?;
    let recorded = read_by_unit(&files, &steps)?;
    let diagnosis_data = args
        .diagnosis_data
        .as_deref()
        .map(|dir| evaluation_segments(dir, &recorded, &outcome.fitted))
        .transpose()?
        .unwrap_or_default();
    // The evaluation data's life starts a day after the diagnosis data's, when both are given.
    let mut before_evaluation = recorded.clone();
    for (unit, extra) in &diagnosis_data {
        before_evaluation
            .entry(unit.clone())
            .or_default()
            .extend(extra.iter().cloned());
    }
    let evaluation = args
        .evaluation_data
        .as_deref()
        .map(|dir| evaluation_segments(dir, &before_evaluation, &outcome.fitted))
        .transpose()?;
    let mut loop_options = LoopOptions {
        select_on: args.select_on.clone(),
        diagnose_on: args.diagnose_on.clone(),
        extend: args.extend,
        ..LoopOptions::new(&options.calibration_set_points)
    };
    loop_options
        .bench_channels
        .extend(args.bench_channels.iter().cloned());
    let mut units: Vec<(String, Closed<'_>, &FittedUnit)> = Vec::new();
    let unit_step = if args.extend {
        "units: refitting on every candidate, shuffle test, guarding the extended model"
    } else {
        "units: refitting on every candidate, shuffle test (99 reshuffles per axis)"
    };
    for (n, (unit, segments)) in recorded.iter().enumerate() {
        // The bar counts units; the loop's own steps within one leave it where it is.
        let within = Within {
            outer: &steps,
            step: unit_step,
            done: n as u64,
            total: recorded.len() as u64,
        };
        steps.update(unit_step, n as u64, recorded.len() as u64);
        let Some(fitted) = outcome.fitted.iter().find(|f| &f.unit_id == unit) else {
            continue;
        };
        let extra: Vec<&Segment> = diagnosis_data.get(unit).into_iter().flatten().collect();
        let halves = match &evaluation {
            None => close_both(
                fitted,
                segments,
                &extra,
                &loop_options,
                &options.fit,
                &within,
            )?,
            Some(evaluation) => {
                let Some(judged) = evaluation.get(unit) else {
                    continue;
                };
                close_separate_both(
                    fitted,
                    segments,
                    judged,
                    &extra,
                    &loop_options,
                    &options.fit,
                    &within,
                )?
            }
        };
        for closed in halves {
            if !closed.series.is_empty() {
                let label = match closed.half {
                    Some(half) => format!("{unit}, half {} of 2", half + 1),
                    None => unit.clone(),
                };
                units.push((label, closed, fitted));
            }
        }
    }
    anyhow::ensure!(
        !units.is_empty(),
        "no activations outside the calibration set points {:?} to diagnose",
        input.calibration
    );
    let floor = match &args.noise_floor {
        Some(dir) => {
            steps.update("measuring the noise floor", 0, 1);
            Some(drift_evaluate::noise_floor::measure(
                dir,
                options.fit.lowpass_window_s,
            )?)
        }
        None => None,
    };
    steps.finish();
    let mut preamble = String::new();
    if let Some(dir) = &args.evaluation_data {
        let _ = writeln!(
            preamble,
            "Calibration data: `{}` (calibration {:?} °C); evaluation data: `{}` (every activation of the fitted units held out; none reaches the tables, a choice, the ranking or the extended model).\n",
            input.source().display(),
            options.calibration_set_points,
            dir.display()
        );
    }
    let request = Request {
        top: args.top,
        extend: args.extend,
        select_on: &args.select_on,
        evaluation_data: args.evaluation_data.as_deref(),
    };
    let mut sections = Vec::new();
    for (unit, closed, fitted) in &units {
        let section =
            diagnosis::unit_section(unit, closed, fitted, &options.fit, &request, floor.as_ref())?;
        print!("{}", section.console);
        sections.push(section);
    }
    let document =
        diagnosis::document(&preamble, &sections, &diagnosis::agreement_markdown(&units));
    diagnosis::write(&out, &document, &sections)?;
    staged.commit()?;
    println!("diagnosis: {}", args.out.join("diagnosis.md").display());
    Ok(())
}

/// Refuses diagnosis data, evaluation data or a noise floor that hold a recording of the campaign
/// (or of each other), compared by content: a copy of the campaign given as `--evaluation-data`
/// would be counted as held out.
fn refuse_shared_inputs(campaign: &[PathBuf], args: &Args) -> anyhow::Result<()> {
    let listed = |dir: &Option<PathBuf>| {
        dir.as_deref()
            .map(pipeline::recording_files)
            .transpose()
            .map(Option::unwrap_or_default)
    };
    let diagnosis = listed(&args.diagnosis_data)?;
    let evaluation = listed(&args.evaluation_data)?;
    let floor = listed(&args.noise_floor)?;
    let apart = "each must be other recordings than the campaign and than each other: give \
                 recordings the campaign does not hold";
    for (flag, files) in [
        ("--diagnosis-data", &diagnosis),
        ("--evaluation-data", &evaluation),
        ("--noise-floor", &floor),
    ] {
        refuse_shared(("the campaign", campaign), (flag, files), apart)?;
    }
    refuse_shared(
        ("--diagnosis-data", &diagnosis),
        ("--evaluation-data", &evaluation),
        apart,
    )
}
