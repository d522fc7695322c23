//! The report's Markdown pieces: the tables' crossings, stage 3's and the warm starts' choices,
//! the rankings, the residual profiles and the halves' agreement.

use std::fmt::Write as _;

use drift_diagnose::closing::{
    mean_profiles, profile_bin_labels, BeforeAfter, Closed, Profile, Stage3Choice,
};
use drift_diagnose::diagnose::AxisDiagnosis;
use drift_diagnose::selection::Selected;
use drift_diagnose::warm_start::WarmStartChoice;
use drift_fit::FittedUnit;

use crate::tables::ten_thousandths;

/// Where the tables' own history lookup fails, as Markdown: no per-sample candidate can carry it
/// (the lookup picks the wrong curve), so it is said before the ranking.
pub(super) fn crossings_markdown(
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
pub(super) fn profile_markdown(profiles: &[Profile]) -> String {
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
    let mut md = String::from("## Diagnosis of the residual after the loop's model (stage 3 and the initial bias as chosen above)\n\nFirst the **baseline**, fitted before any candidate and never a discovery: the paper model's known ambient gap (the tables read at the chamber air logged at switch-on, less the paper's reading at the switch-on temperature) and the bench's context channels (the chamber air, alone and times the rise and the temperature). Then each candidate, stripped first of what the paper's model already accounts for (the paper's tables are fitted to the candidate itself on the calibration activations with the drift fit's reference times, and what they predict of it is taken out: “absorbed by the model”), is scored by its **gain**: the out-of-sample share of the residual's variance it explains beyond the baseline (cross-validated with whole series held out together, at the better of two levels: shapes within activations, offsets between them; 0 when the folds' coefficients disagree in sign). **Selection** is forward, in two steps: first the unit's **own thermal response** beyond the tables (its rise squared and its own axis's temperature rate, the sensor's or the lagging element's: what a thermal calibration in T, T² and a filtered dT/dt holds), then the **effects** (every other candidate) over the baseline and the thermal response selected. In each step the best candidate is selected when it is significant family-wise (α = 0.05: whole series' candidates are shuffled onto other series of the same unit and set point 99 times, and the best of all candidates reached its gain in at most 5 % of the shuffles: p family) **and** its gain reaches the step's size threshold (the 95th percentile of the top gain on null worlds for this many activations: τ for effects, τ response for the thermal response); it then joins the baseline and the rest are scored again, up to four in all. *Detectable*: the larger of chance's 5 % level and τ, for an effect. The per-activation t-tests at the candidate's level (p) and on the whole residual (p whole), on what the baseline leaves, are shown, not gated on.\n\n");
    for axis in axes {
        let _ = writeln!(
            md,
            "### Axis {} ({} activations, residual RMS {:.4} °/s, detectable gain {:.3}, τ {:.3}, τ response {:.3}): {}\n",
            axis.axis,
            axis.activations,
            axis.residual_rms_dps,
            axis.detectable_share,
            axis.size_threshold,
            axis.response_size_threshold,
            selections(axis, &|s| format!("**{}** (gain {:.3}, p family {:.2})", s.name, s.gain, s.family_p_value))
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
                match (c.significant, c.thermal_response) {
                    (true, true) => "thermal response",
                    (true, false) => "effect",
                    _ => "",
                },
                c.coefficient,
                c.absorbed_by_model
            );
        }
        md.push('\n');
    }
    md
}

/// An axis's selections in words, the thermal response and the effects apart, each selection
/// written by `one`.
pub(super) fn selections(axis: &AxisDiagnosis, one: &dyn Fn(&Selected) -> String) -> String {
    let list = |response: bool| {
        let picked: Vec<String> = axis
            .selected
            .iter()
            .filter(|s| s.thermal_response == response)
            .map(one)
            .collect();
        picked.join(", then ")
    };
    let (response, effects) = (list(true), list(false));
    match (response.is_empty(), effects.is_empty()) {
        (true, true) => "nothing beyond the baseline and chance".to_owned(),
        (false, true) => {
            format!("the unit's own thermal response {response}; no effect beyond it and chance")
        }
        (true, false) => format!("effect {effects}"),
        (false, false) => format!("the unit's own thermal response {response}; effect {effects}"),
    }
}

/// The ranking behind the paper's own model, when the loop changed it: what the paper's model
/// lacked, which the choices above answer; the section before it says what is left.
pub(super) fn paper_markdown(axes: &[AxisDiagnosis], top: usize) -> String {
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

/// Per axis, the significant winning effect and the admitted terms of one half's loop.
fn findings(closed: &Closed<'_>) -> [(String, Vec<String>); 3] {
    std::array::from_fn(|axis| {
        let winner = closed.axes[axis]
            .chosen()
            .map_or_else(|| "no effect significant".to_owned(), |c| c.name.clone());
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
pub fn agreement_markdown(units: &[(String, Closed<'_>, &FittedUnit)]) -> String {
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
