//! `gyrodrift diagnose`: which quantity explains what the paper's model leaves in the residual?

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use drift_fit::diagnose::{diagnose, series, ActivationSeries, AxisDiagnosis, CandidateScore};
use drift_fit::pipeline;
use drift_recording::{read_recording, Segment, SeriesKind};
use rayon::prelude::*;

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use crate::output::write_atomic;
use crate::report::plots;

/// One unit's activations, split for `--extend`.
#[derive(Default)]
struct UnitSegments {
    calibration: Vec<Segment>,
    training: Vec<Segment>,
    validation: Vec<Segment>,
}

/// Options of `gyrodrift diagnose`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Recordings and fit settings.
    #[command(flatten)]
    pub input: CampaignArgs,
    /// Output folder for `diagnosis.md` and `diagnosis.json`.
    #[arg(long, short = 'o', default_value = "out/diagnosis")]
    pub out: PathBuf,
    /// How many candidates to print per axis.
    #[arg(long, default_value_t = 5)]
    pub top: usize,
    /// Close the loop: add the significant winners as the extended model's terms, fit their
    /// coefficients on the field-like activations at the calibration set points (which the
    /// diagnosis then leaves out), refit the tables, and report the error before and after.
    #[arg(long)]
    pub extend: bool,
}

/// The ranking as Markdown.
pub fn markdown(axes: &[AxisDiagnosis], top: usize) -> String {
    let mut md = String::from("## Diagnosis of the residual after the paper's model\n\nCandidates ranked by out-of-sample explained variance (5-fold cross-validation by activation), each stripped first of what the paper's model already accounts for (time since switch-on, rise, the model's drift estimate, ambient). Significant: one-sided test of the held-out improvement per activation, Bonferroni over the axis's candidates, family-wise α = 0.05.\n\n");
    for axis in axes {
        let _ = writeln!(
            md,
            "### Axis {} ({} activations, residual RMS {:.4} °/s): {}\n",
            axis.axis,
            axis.activations,
            axis.residual_rms_dps,
            axis.chosen().map_or(
                "no significant systematic effect left".to_owned(),
                |c| format!("**{}**", c.name)
            )
        );
        md.push_str("| rank | candidate | level | explained | p | significant | coefficient | absorbed by the model |\n|---:|---|---|---:|---:|:---:|---:|---:|\n");
        for (i, c) in axis.ranking.iter().take(top).enumerate() {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.3} | {:.1e} | {} | {:.3e} | {:.3} |",
                i + 1,
                c.name,
                c.level,
                c.explained,
                c.p_value,
                if c.significant { "yes" } else { "" },
                c.coefficient,
                c.absorbed_by_model
            );
        }
        md.push('\n');
    }
    md
}

/// The residual against the top candidate of an axis, at the level where the candidate scored:
/// activation means (between) or points less their activation means (within, every 10th point).
fn residual_plot(
    activations: &[ActivationSeries],
    axis: usize,
    top: &CandidateScore,
) -> anyhow::Result<String> {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let points: Vec<(f64, f64)> = if top.level == "between activations" {
        activations
            .iter()
            .map(|a| {
                (
                    mean(&a.candidates[axis][&top.name]),
                    mean(&a.residual_dps[axis]),
                )
            })
            .collect()
    } else {
        activations
            .iter()
            .flat_map(|a| {
                let c = &a.candidates[axis][&top.name];
                let r = &a.residual_dps[axis];
                let (mc, mr) = (mean(c), mean(r));
                c.iter()
                    .zip(r)
                    .step_by(10)
                    .map(move |(c, r)| (c - mc, r - mr))
            })
            .collect()
    };
    let title = format!("Residual against {} ({})", top.name, top.level);
    let x = if top.level == "between activations" {
        top.name.clone()
    } else {
        format!("{} − its activation mean", top.name)
    };
    plots::draw(
        &plots::Chart {
            title: &title,
            x: &x,
            y: "residual, °/s",
        },
        &[plots::Series::markers(top.name.clone(), points)],
    )
}

/// Runs `gyrodrift diagnose`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let input = &args.input;
    let options = input.options(&[], false)?;
    let files = pipeline::recording_files(&input.campaign)?;
    let steps = Steps::new(input.quiet);
    let outcome = pipeline::run(&files, &options, false, &|s, d, t| steps.update(s, d, t))
        .map_err(|e| super::measured::explain(e, &files))?;
    // Every activation the fit did not see: field sessions and non-calibration set points. With
    // --extend, the field sessions at the calibration set points train the terms instead.
    let mut by_unit: BTreeMap<String, Vec<ActivationSeries>> = BTreeMap::new();
    let mut kept: BTreeMap<String, UnitSegments> = BTreeMap::new();
    for (i, path) in files.iter().enumerate() {
        steps.update(
            "putting unseen activations on the diagnosis grid",
            i as u64,
            files.len() as u64,
        );
        if !args.extend && pipeline::calibration_file(path, &options)? == Some(true) {
            continue;
        }
        let recording = read_recording(path)?;
        let Some(fitted) = outcome
            .fitted
            .iter()
            .find(|f| f.unit_id == recording.unit_id)
        else {
            continue;
        };
        let training = |s: &Segment| {
            args.extend
                && s.labels.series_kind == SeriesKind::Field
                && options
                    .calibration_set_points
                    .iter()
                    .any(|c| (c - s.labels.set_point_celsius).abs() < 1e-6)
        };
        let prepared: Vec<ActivationSeries> = recording
            .segments
            .par_iter()
            .filter(|s| !pipeline::calibration_segment(s, &options) && !training(s))
            .map(|s| series(fitted, s, &options.fit))
            .collect();
        if args.extend {
            let unit = kept.entry(recording.unit_id.clone()).or_default();
            for segment in recording.segments {
                if pipeline::calibration_segment(&segment, &options) {
                    unit.calibration.push(segment);
                } else if training(&segment) {
                    unit.training.push(segment);
                } else {
                    unit.validation.push(segment);
                }
            }
        }
        by_unit
            .entry(recording.unit_id.clone())
            .or_default()
            .extend(prepared);
    }
    steps.finish();
    anyhow::ensure!(
        !by_unit.is_empty(),
        "no activations outside the calibration set points {:?} to diagnose",
        input.calibration
    );
    let mut md = String::from("# gyrodrift diagnosis\n\n");
    let mut json = Vec::new();
    for (unit, activations) in &by_unit {
        let axes = diagnose(activations);
        let _ = writeln!(md, "# Unit {unit}\n");
        md.push_str(&markdown(&axes, args.top));
        println!("{unit}:");
        for axis in &axes {
            let chosen = axis
                .chosen()
                .map_or("no significant systematic effect left".to_owned(), |c| {
                    format!("{} (explains {:.0} %)", c.name, 100.0 * c.explained)
                });
            println!("  {}: {chosen}", axis.axis);
            for (i, c) in axis.ranking.iter().take(args.top).enumerate() {
                println!(
                    "     {}. {:<42} {:<20} explained {:>6.3}  p {:.1e}{}",
                    i + 1,
                    c.name,
                    c.level,
                    c.explained,
                    c.p_value,
                    if c.significant { "  *" } else { "" }
                );
            }
        }
        for (axis_index, axis) in axes.iter().enumerate() {
            if let Some(top) = axis
                .ranking
                .first()
                .filter(|c| c.level != "absorbed by the model")
            {
                let file = format!("residual-{unit}-{}.svg", axis.axis);
                write_atomic(
                    &args.out.join(&file),
                    residual_plot(activations, axis_index, top)?.as_bytes(),
                )?;
                let _ = writeln!(
                    md,
                    "![Residual of unit {unit}, axis {}, against {}]({file})\n",
                    axis.axis, top.name
                );
            }
        }
        if let (true, Some(segments), Some(fitted)) = (
            args.extend,
            kept.get(unit),
            outcome.fitted.iter().find(|f| &f.unit_id == unit),
        ) {
            md.push_str(&super::extend::run(
                unit,
                &axes,
                fitted,
                &super::extend::Roles {
                    calibration: segments.calibration.iter().collect(),
                    training: segments.training.iter().collect(),
                    validation: segments.validation.iter().collect(),
                },
                &options.fit,
                &args.out,
            )?);
        }
        json.push(serde_json::json!({ "unit": unit, "axes": axes }));
    }
    write_atomic(&args.out.join("diagnosis.md"), md.as_bytes())?;
    write_atomic(
        &args.out.join("diagnosis.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    println!("diagnosis: {}", args.out.join("diagnosis.md").display());
    Ok(())
}
