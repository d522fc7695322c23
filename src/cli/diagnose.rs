//! `gyrodrift diagnose`: which quantity explains what the paper's model leaves in the residual?

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use drift_fit::diagnose::{diagnose, series, ActivationSeries, AxisDiagnosis};
use drift_fit::pipeline;
use drift_recording::read_recording;
use rayon::prelude::*;

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use crate::output::write_atomic;

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

/// Runs `gyrodrift diagnose`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let input = &args.input;
    let options = input.options(&[], false)?;
    let files = pipeline::recording_files(&input.campaign)?;
    let steps = Steps::new(input.quiet);
    let outcome = pipeline::run(&files, &options, false, &|s, d, t| steps.update(s, d, t))?;
    // Every activation the fit did not see: field sessions and non-calibration set points.
    let mut by_unit: BTreeMap<String, Vec<ActivationSeries>> = BTreeMap::new();
    for (i, path) in files.iter().enumerate() {
        steps.update(
            "putting unseen activations on the diagnosis grid",
            i as u64,
            files.len() as u64,
        );
        if pipeline::calibration_file(path, &options)? == Some(true) {
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
        let prepared: Vec<ActivationSeries> = recording
            .segments
            .par_iter()
            .filter(|s| !pipeline::calibration_segment(s, &options))
            .map(|s| series(fitted, s, &options.fit))
            .collect();
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
