//! `gyrodrift diagnose`: which quantity explains what the paper's model leaves in the residual?

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use drift_diagnose::activations::{loop_settings, read_by_unit, DIAGNOSIS_RATE_HZ};
use drift_diagnose::closing::{
    close_both, close_separate_both, mean_profiles, profile_bin_labels, BeforeAfter, Closed,
    LoopOptions, Profile, Stage3Choice,
};
use drift_diagnose::diagnose::{ActivationSeries, AxisDiagnosis, CandidateScore};
use drift_diagnose::warm_start::WarmStartChoice;
use drift_evaluate::pipeline;
use drift_fit::FittedUnit;
use drift_recording::output_folder::{Owned, Writer};
use drift_recording::Segment;

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use super::shared_data::refuse_shared;
use drift_report::plots;
use drift_report::tables::ten_thousandths;
use drift_report::write_atomic;

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
    let mut units = read_by_unit(&files, |_, _| {})?;
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

/// Where the tables' own history lookup fails, as Markdown: no per-sample candidate can carry it
/// (the lookup picks the wrong curve), so it is said before the ranking.
fn crossings_markdown(
    fitted: &FittedUnit,
    stage3: &[Stage3Choice; 3],
    warm_start: &[WarmStartChoice; 3],
    held_out: &[BeforeAfter],
) -> String {
    let mut md = if fitted.crossings.is_empty() {
        String::from("The calibration curves keep the paper's order (a warmer start rises less at every moment), so stage 3 can tell heating histories apart by the rise.\n\n")
    } else {
        crossings_table(fitted)
    };
    md.push_str(&stage3_table(stage3));
    md.push_str(&warm_start_table(warm_start));
    if !held_out.is_empty() {
        md.push_str(&history_table(held_out));
    }
    md
}

/// Where the calibration curves cross, as Markdown.
fn crossings_table(fitted: &FittedUnit) -> String {
    let mut md = String::from("## The tables' history lookup\n\nStage 3 finds an activation's heating history by its rise, which assumes a warmer start rises less. In these calibration curves warmer starts rise more (worst pair per set point and axis); stage 3 then reads the drift/rise ratio of another history on every activation. No term of the candidates below repairs a wrong lookup; the same curves keyed by the residual heat at switch-on (`by_history.bin` of `gyrodrift fit`, for firmware that keeps what it knew of the previous activation) choose them by history instead: their error on the held-out activations follows the table. The stage-3 oracle of experiments/ measures what the lookup costs.\n\n| set point | axis | warmer start | colder start | switched on warmer by | rises more by | at | pairs crossing |\n|---:|---|---|---|---:|---:|---:|---:|\n");
    for c in &fitted.crossings {
        let _ = writeln!(
            md,
            "| {:+.1} °C | {} | {} | {} | {:.2} °C | {:.3} °C | {:.1} s | {} of {} |",
            c.set_point_celsius,
            ["X", "Y", "Z"][c.axis],
            c.warmer.name(),
            c.colder.name(),
            c.switched_on_warmer_by_celsius,
            c.rise_excess_celsius,
            f64::from(c.at_ms) / 1000.0,
            c.crossing_pairs,
            c.compared_pairs
        );
    }
    md
}

/// The stage-3 choice per axis, as Markdown.
fn stage3_table(stage3: &[Stage3Choice; 3]) -> String {
    if stage3.iter().all(|c| c.training_activations == 0) {
        return String::from("\n## Stage 3: keyed by rise or by heating history\n\nNo field-like activations at the calibration set points to choose on: stage 3 keeps the paper's lookup by rise on every axis (`gyrodrift simulate --field` records some).\n\n");
    }
    let mut md = String::from("\n## Stage 3: keyed by rise or by heating history\n\nChosen per axis on the training activations (field-like use at the calibration set points; the held-out ones are only measured): keyed by history where that leaves significantly less drift (paired by activation, one-sided, 5 %). The diagnosis below looks behind the chosen model.\n\n| axis | curves cross | training activations | drift keyed by rise | drift keyed by history | p | stage 3 |\n|---|---|---:|---:|---:|---:|---|\n");
    for c in stage3 {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.4} | {:.4} | {:.1e} | {} |",
            c.axis,
            if c.curves_cross { "yes" } else { "no" },
            c.training_activations,
            c.training_drift_by_rise_dps,
            c.training_drift_by_history_dps,
            c.p_value,
            if c.keyed_by_history {
                "**keyed by history**"
            } else {
                "keyed by rise"
            }
        );
    }
    md.push('\n');
    md
}

/// The initial-bias choice per axis, as Markdown (nothing without training activations: the stage-3
/// section already says there was nothing to choose on).
fn warm_start_table(warm_start: &[WarmStartChoice; 3]) -> String {
    if warm_start.iter().all(|c| c.training_activations == 0) {
        return String::new();
    }
    let mut md = String::from("\n## Initial bias: the paper's or the warm starts'\n\nThe paper reads the initial bias from the switch-on temperature alone. After a short off-time the sensing element is not at the sensor's temperature and is still cooling, so the bias starts elsewhere; the calibration's series measured where at each of their off-times (`warm_starts` of `by_history.bin`). Chosen per axis on the training activations, after stage 3: the warm starts' initial bias where it leaves a significantly smaller mean square error (paired by activation, one-sided, 5 %). The drift (max − min) cannot see an offset; the RMS can.\n\n| axis | training activations | RMS, paper's initial bias | RMS, warm starts' | p | initial bias |\n|---|---:|---:|---:|---:|---|\n");
    for c in warm_start {
        let _ = writeln!(
            md,
            "| {} | {} | {:.4} | {:.4} | {:.1e} | {} |",
            c.axis,
            c.training_activations,
            c.training_rms_cold_dps,
            c.training_rms_warm_dps,
            c.p_value,
            if c.chosen {
                "**warm starts'**"
            } else {
                "the paper's"
            }
        );
    }
    md.push('\n');
    md
}

/// Mean drift per set point, series kind and axis of the held-out activations with stage 3 keyed
/// by rise (the paper's) and by history.
fn history_table(held_out: &[BeforeAfter]) -> String {
    let groups = drift_diagnose::before_after::by_group(held_out);
    let mut md = String::from("\n| held out | activations | drift keyed by rise X / Y / Z | drift keyed by history X / Y / Z |\n|---|---:|---|---|\n");
    for (key, rows) in &groups {
        let n = rows.len() as f64;
        let mean = |f: &dyn Fn(&BeforeAfter) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / n;
        let three = |f: &dyn Fn(&BeforeAfter, usize) -> f64| {
            (0..3)
                .map(|a| format!("{:.4}", mean(&|r| f(r, a))))
                .collect::<Vec<_>>()
                .join(" / ")
        };
        let _ = writeln!(
            md,
            "| {key} | {} | {} | {} |",
            rows.len(),
            three(&|r, a| r.drift_dps[a].0),
            three(&|r, a| r.by_history_drift_dps[a]),
        );
    }
    md.push_str("\nDrift in °/s (max − min of the 1-s mean per activation); keyed by history, each activation starts from what firmware kept of the one before (with a clock that tells a full cool-down).\n\n");
    md
}

/// Where within the held-out activations the loop's residual sits, as Markdown: per set point, the
/// mean profile of each group (the protocol, the field by off-time before) and axis.
fn profile_markdown(profiles: &[Profile]) -> String {
    let bins = profile_bin_labels();
    let mut md = String::from("## Where within the held-out activations the residual sits\n\n");
    md.push_str("The loop's model's residual (1-s mean) less each activation's own mean, averaged over the activations of a group in bins of time since switch-on, 10⁻⁴ °/s. An offset does not show here; a transient after switch-on, or a ramp, does — and when it happens, which the drift metric (max − min) does not say. After a short off-time, a transient that fades within a minute is a warm start the model does not follow (docs/closed-loop.md, *Reading the report*).\n\n");
    let mut set_points: Vec<f64> = profiles.iter().map(|p| p.set_point_celsius).collect();
    set_points.sort_by(f64::total_cmp);
    set_points.dedup();
    for set_point in set_points {
        let here: Vec<&Profile> = profiles
            .iter()
            .filter(|p| p.set_point_celsius == set_point)
            .collect();
        let _ = writeln!(md, "**{set_point:+} °C**\n");
        let _ = writeln!(md, "| group | axis | {} |", bins.join(" | "));
        let _ = writeln!(md, "|---|---|{}", "---:|".repeat(bins.len()));
        for (group, count, means) in mean_profiles(&here) {
            for (axis, means) in ["X", "Y", "Z"].iter().zip(means) {
                let cells = ten_thousandths(&means);
                let _ = writeln!(md, "| {group} ({count}) | {axis} | {} |", cells.join(" | "));
            }
        }
        md.push('\n');
    }
    md
}

/// The ranking as Markdown.
pub fn markdown(axes: &[AxisDiagnosis], top: usize) -> String {
    let mut md = String::from("## Diagnosis of the residual after the loop's model (stage 3 and the initial bias as chosen above)\n\nFirst the **baseline**, fitted before any candidate and never a discovery: the paper model's known ambient gap (the tables read at the chamber air logged at switch-on, less the paper's reading at the switch-on temperature) and the bench's context channels (the chamber air, alone and times the rise and the temperature). Then each candidate, stripped first of what the paper's model already accounts for (the paper's tables are fitted to the candidate itself on the calibration activations with the drift fit's reference times, and what they predict of it is taken out: “absorbed by the model”), is scored by its **gain**: the out-of-sample share of the residual's variance it explains beyond the baseline (cross-validated with whole series held out together, at the better of two levels: shapes within activations, offsets between them; 0 when the folds' coefficients disagree in sign). **Selection** is forward: the best candidate is selected when it is significant family-wise (α = 0.05: whole series' candidates are shuffled onto other series of the same unit and set point 99 times, and the best of all candidates reached its gain in at most 5 % of the shuffles: p family) **and** its gain reaches the size threshold τ (the 95th percentile of the top gain on null worlds for this many activations); it then joins the baseline and the rest are scored again, up to four. *Detectable*: the larger of chance's 5 % level and τ. The per-activation t-tests at the candidate's level (p) and on the whole residual (p whole), on what the baseline leaves, are shown, not gated on.\n\n");
    for axis in axes {
        let _ = writeln!(
            md,
            "### Axis {} ({} activations, residual RMS {:.4} °/s, detectable gain {:.3}, τ {:.3}): {}\n",
            axis.axis,
            axis.activations,
            axis.residual_rms_dps,
            axis.detectable_share,
            axis.size_threshold,
            if axis.selected.is_empty() {
                "nothing beyond the baseline and chance".to_owned()
            } else {
                axis.selected
                    .iter()
                    .map(|s| format!("**{}** (gain {:.3}, p family {:.2})", s.name, s.gain, s.family_p_value))
                    .collect::<Vec<_>>()
                    .join(", then ")
            }
        );
        let _ = writeln!(
            md,
            "Baseline: {} — explains {:.3} of the residual's variance within activations and {:.3} of the activations' means, out of sample.\n",
            if axis.baseline.is_empty() {
                "none (no chamber air logged)".to_owned()
            } else {
                axis.baseline.join("; ")
            },
            axis.baseline_explained_within,
            axis.baseline_explained_between
        );
        md.push_str("| rank | candidate | level | gain | p family | p | p whole | selected | coefficient | absorbed by the model |\n|---:|---|---|---:|---:|---:|---:|:---:|---:|---:|\n");
        for (i, c) in axis.ranking.iter().take(top).enumerate() {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.3} | {:.2} | {:.1e} | {:.1e} | {} | {:.3e} | {:.3} |",
                i + 1,
                c.name,
                c.level,
                c.explained,
                c.family_p_value,
                c.p_value,
                c.whole_p_value,
                if c.significant { "yes" } else { "" },
                c.coefficient,
                c.absorbed_by_model
            );
        }
        md.push('\n');
    }
    md
}

/// The ranking behind the paper's own model, when the loop changed it: what the paper's model
/// lacked, which the choices above answer; the section before it says what is left.
fn paper_markdown(axes: &[AxisDiagnosis], top: usize) -> String {
    let mut md = String::from("## What the paper's model lacked\n\nThe same diagnosis, on the same activations, behind the paper's model (stage 3 keyed by rise, the paper's initial bias): what the choices above answer.\n\n| axis | residual RMS | top candidates (explained, level) | significant |\n|---|---:|---|---|\n");
    for axis in axes {
        let ranked: Vec<String> = axis
            .ranking
            .iter()
            .take(top)
            .map(|c| format!("{} ({:.3}, {})", c.name, c.explained, c.level))
            .collect();
        let significant: Vec<&str> = axis
            .ranking
            .iter()
            .filter(|c| c.significant)
            .map(|c| c.name.as_str())
            .collect();
        let _ = writeln!(
            md,
            "| {} | {:.4} | {} | {} |",
            axis.axis,
            axis.residual_rms_dps,
            ranked.join("; "),
            if significant.is_empty() {
                "–".to_owned()
            } else {
                significant.join(", ")
            }
        );
    }
    md.push('\n');
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
                    mean(&a.left_over[axis][&top.name]),
                    mean(&a.residual_dps[axis]),
                )
            })
            .collect()
    } else {
        activations
            .iter()
            .flat_map(|a| {
                let c = &a.left_over[axis][&top.name];
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
        format!("{}, less what the tables predict of it", top.name)
    } else {
        format!(
            "{}, less what the tables predict of it, less its activation mean",
            top.name
        )
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

/// Writes each axis's plot of the residual against its top candidate (unless the model absorbs
/// it) and returns the report's links to them.
fn residual_plots(
    unit: &str,
    activations: &[ActivationSeries],
    axes: &[AxisDiagnosis],
    out: &std::path::Path,
) -> anyhow::Result<String> {
    let mut md = String::new();
    for (axis_index, axis) in axes.iter().enumerate() {
        if let Some(top) = axis
            .ranking
            .first()
            .filter(|c| c.level != "absorbed by the model")
        {
            let file = format!("residual-{unit}-{}.svg", axis.axis);
            write_atomic(
                &out.join(&file),
                residual_plot(activations, axis_index, top)?.as_bytes(),
            )?;
            let _ = writeln!(
                md,
                "![Residual of unit {unit}, axis {}, against {}]({file})\n",
                axis.axis, top.name
            );
        }
    }
    Ok(md)
}

/// Per axis, the significant winner and the admitted terms of one half's loop.
fn findings(closed: &Closed<'_>) -> [(String, Vec<String>); 3] {
    std::array::from_fn(|axis| {
        let winner = closed.axes[axis]
            .chosen()
            .map_or_else(|| "nothing significant".to_owned(), |c| c.name.clone());
        let admitted = closed
            .extended
            .iter()
            .flat_map(|e| e.admissions.iter())
            .filter(|a| a.admitted && a.axis == closed.axes[axis].axis)
            .map(|a| a.candidate.clone())
            .collect();
        (winner, admitted)
    })
}

/// With the diagnosis data cross-fitted, whether the two halves found and admitted the same, per
/// unit and axis: a finding one half alone makes is not yet a finding.
fn agreement_markdown(units: &[(String, Closed<'_>, &FittedUnit)]) -> String {
    let mut md = String::new();
    for pair in units.windows(2) {
        let [(first, a, unit_a), (_, b, unit_b)] = pair else {
            continue;
        };
        if unit_a.unit_id != unit_b.unit_id || !first.ends_with("half 1 of 2") {
            continue;
        }
        let _ = writeln!(
            md,
            "# Unit {}: do the halves agree?

Each half ranked, fitted and guarded on its own series and was judged on the other's.

| axis | half 1: significant winner | half 2: significant winner | half 1: admitted | half 2: admitted | agree |\n|---|---|---|---|---|---|",
            unit_a.unit_id
        );
        for ((axis, (wa, ta)), (wb, tb)) in ["X", "Y", "Z"].iter().zip(findings(a)).zip(findings(b))
        {
            let list = |t: &[String]| {
                if t.is_empty() {
                    "–".to_owned()
                } else {
                    t.join(", ")
                }
            };
            let _ = writeln!(
                md,
                "| {axis} | {wa} | {wb} | {} | {} | {} |",
                list(&ta),
                list(&tb),
                if wa == wb && ta == tb { "yes" } else { "no" }
            );
        }
        md.push('\n');
    }
    md
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
    let outcome = pipeline::fit_at_rate(&files, &options, DIAGNOSIS_RATE_HZ, &|s, d, t| {
        steps.update(s, d, t)
    })
    .map_err(|e| super::measured::explain(e, &files))?;
    let recorded = read_by_unit(&files, |done, total| {
        steps.update("reading activations by role", done, total)
    })?;
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
    for (n, (unit, segments)) in recorded.iter().enumerate() {
        steps.update(
            if args.extend {
                "units: refitting on every candidate, shuffle test, guarding the extended model"
            } else {
                "units: refitting on every candidate, shuffle test (99 reshuffles per axis)"
            },
            n as u64,
            recorded.len() as u64,
        );
        let Some(fitted) = outcome.fitted.iter().find(|f| &f.unit_id == unit) else {
            continue;
        };
        let extra: Vec<&Segment> = diagnosis_data.get(unit).into_iter().flatten().collect();
        let halves = match &evaluation {
            None => close_both(fitted, segments, &extra, &loop_options, &options.fit)?,
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
    let mut md = String::from("# gyrodrift diagnosis\n\n");
    if let Some(dir) = &args.evaluation_data {
        let _ = writeln!(
            md,
            "Calibration data: `{}` (calibration {:?} °C); evaluation data: `{}` (every activation of the fitted units held out; none reaches the tables, a choice, the ranking or the extended model).\n",
            input.source().display(),
            options.calibration_set_points,
            dir.display()
        );
    }
    let mut json = Vec::new();
    for (unit, closed, fitted) in &units {
        // Files are named by unit and half, without the heading's spaces and commas.
        let stem = match closed.half {
            Some(half) => format!("{}-half{}", fitted.unit_id, half + 1),
            None => fitted.unit_id.clone(),
        };
        let (activations, axes, roles) = (&closed.series, &closed.axes, &closed.roles);
        let _ = writeln!(md, "# Unit {unit}\n");
        {
            let _ = writeln!(
                md,
                "Diagnosed on {} activations the fit never saw ({}{}); {} field-like activations at the calibration set points switched on outside the calibrated ambient range (the model clamps there by design) and are {}.\n",
                activations.len(),
                if roles.training.is_empty() && roles.selection.is_empty() {
                    if roles.not_judged.is_empty() {
                        "every activation outside the calibration protocol"
                    } else {
                        "the calibration data's activations outside the calibration protocol"
                    }
                } else {
                    "field-like activations at the calibration set points"
                },
                if roles.selection.is_empty() {
                    String::new()
                } else {
                    format!(
                        " and {} protocol activations at {:?} °C, not measured on afterwards",
                        roles.selection.len(),
                        args.select_on
                    )
                } + &if roles.diagnosis.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; and {} activations of this half of the analyst's diagnosis series, ranked, fitted and guarded on, while the other half's series are held out and judge",
                        roles.diagnosis.len()
                    )
                },
                roles.outside_range,
                if args.evaluation_data.is_some() {
                    "not judged on, as the calibration data's other activations".to_owned()
                } else {
                    format!("held out with the rest ({} held out in all)", roles.held_out.len())
                }
            );
            if let Some(dir) = &args.evaluation_data {
                let _ = writeln!(
                    md,
                    "Held out: the {} activations of the evaluation data `{}`; the calibration data's {} activations outside the roles above are not judged on.\n",
                    roles.held_out.len(),
                    dir.display(),
                    roles.not_judged.len()
                );
            }
        }
        // The held-out errors are needed by the crossings' table and the extended model's; a
        // unit with neither does not pay for correcting every held-out activation twice more.
        let before_after =
            if fitted.crossings.is_empty() && closed.extended.is_none() && !closed.keying.any() {
                Vec::new()
            } else {
                closed.before_after(fitted, &options.fit)
            };
        let stage3 = &closed.stage3;
        let warm_start = &closed.warm_start;
        md.push_str(&crossings_markdown(
            fitted,
            stage3,
            warm_start,
            &before_after,
        ));
        md.push_str(&markdown(axes, args.top));
        // The plots show the ranking just above them (behind the loop's model), so they follow
        // it rather than the paper's ranking.
        md.push_str(&residual_plots(&stem, activations, axes, &out)?);
        if closed.keying.any() {
            md.push_str(&paper_markdown(&closed.paper_axes, args.top));
        }
        println!("{unit}:");
        if let Some(dir) = &args.evaluation_data {
            println!(
                "  held out: {} activations of the evaluation data {} ({} of the calibration data's not judged on)",
                closed.roles.held_out.len(),
                dir.display(),
                closed.roles.not_judged.len()
            );
        }
        for crossing in &fitted.crossings {
            println!("  tables: {}", crossing.note());
        }
        if stage3.iter().all(|c| c.training_activations == 0) {
            println!("  stage 3: no field-like activations at the calibration set points to choose on; keyed by rise");
        }
        for c in stage3.iter().filter(|c| c.training_activations > 0) {
            println!(
                "  stage 3 on {}: drift on {} training activations {:.4} keyed by rise, {:.4} by history (p {:.1e}) → {}",
                c.axis,
                c.training_activations,
                c.training_drift_by_rise_dps,
                c.training_drift_by_history_dps,
                c.p_value,
                if c.keyed_by_history { "keyed by history" } else { "keyed by rise" }
            );
        }
        for c in warm_start.iter().filter(|c| c.training_activations > 0) {
            println!(
                "  initial bias on {}: RMS on {} training activations {:.4} with the paper's, {:.4} with warm starts' (p {:.1e}) → {}",
                c.axis,
                c.training_activations,
                c.training_rms_cold_dps,
                c.training_rms_warm_dps,
                c.p_value,
                if c.chosen { "warm starts'" } else { "the paper's" }
            );
        }
        if closed.keying.any() {
            for axis in &closed.paper_axes {
                println!(
                    "  behind the paper's model, {}: {}",
                    axis.axis,
                    axis.ranking.first().map_or("–".to_owned(), |c| format!(
                        "{} explained {:.3}{}",
                        c.name,
                        c.explained,
                        if c.significant { ", significant" } else { "" }
                    ))
                );
            }
        }
        for axis in axes.iter() {
            let chosen = if axis.selected.is_empty() {
                format!(
                    "nothing beyond the baseline (which explains {:.0} % within activations) and chance: with these activations only a gain above {:.0} % would show",
                    100.0 * axis.baseline_explained_within,
                    100.0 * axis.detectable_share
                )
            } else {
                axis.selected
                    .iter()
                    .map(|c| {
                        format!(
                            "{} (gain {:.0} % over the baseline; τ {:.0} %, p family {:.2})",
                            c.name,
                            100.0 * c.gain,
                            100.0 * axis.size_threshold,
                            c.family_p_value
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", then ")
            };
            println!("  {}: {chosen}", axis.axis);
            for (i, c) in axis.ranking.iter().take(args.top).enumerate() {
                println!(
                    "     {}. {:<42} {:<20} gain {:>6.3}  p family {:.2}{}",
                    i + 1,
                    c.name,
                    c.level,
                    c.explained,
                    c.family_p_value,
                    if c.significant { "  *" } else { "" }
                );
            }
        }
        if args.extend {
            println!(
                "  extended model: {}",
                super::extend::verdict(&stem, closed)
            );
        }
        let profiles = closed.profiles(fitted, &options.fit);
        md.push_str(&profile_markdown(&profiles));
        if args.extend {
            md.push_str(&super::extend::run(
                &stem,
                closed,
                fitted,
                &before_after,
                floor.as_ref(),
                &out,
            )?);
        }
        json.push(serde_json::json!({
            "unit": &fitted.unit_id,
            "half": closed.half,
            "axes": axes,
            "paper_axes": &closed.paper_axes,
            "proposed_terms": closed.proposed.terms.iter().map(|t| &t.candidate).collect::<Vec<_>>(),
            "admissions": closed.extended.as_ref().map(|e| &e.admissions),
            "switch_on_rate": closed.extended.is_some().then_some(&closed.switch_on_rate),
            "crossings": fitted.crossings,
            "stage3": stage3,
            "warm_start": warm_start,
            "before_after": before_after,
            // The per-group table of the Markdown, with the noise floor and each excess cut's
            // interval, as data.
            "held_out_error": drift_diagnose::before_after::group_errors(&before_after, floor.as_ref()),
            "noise_floor_given": floor.is_some(),
            "profiles": profiles,
        }));
    }
    md.push_str(&agreement_markdown(&units));
    write_atomic(&out.join("diagnosis.md"), md.as_bytes())?;
    write_atomic(
        &out.join("diagnosis.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
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
