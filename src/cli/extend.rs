//! `gyrodrift diagnose --extend`: the diagnosis's significant winners are offered as the extended
//! model's extra terms; a guard admits each on an axis only where it lowers the error on held-out
//! field-like activations at the calibration set points (the ones the diagnosis ranked on), their
//! coefficients are fitted there, the tables refitted, and the error before and after is reported
//! on the activations nothing was fitted or chosen on (other set points and sessions).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use drift_core::blob;
use drift_fit::diagnose::AxisDiagnosis;
use drift_fit::evaluate::{self, switch_on_raw};
use drift_fit::extend::{correct_with_terms, extend, Extended, TermPlan};
use drift_fit::roles::Roles;
use drift_fit::{FitSettings, FittedUnit};

use crate::output::write_atomic;

/// Per axis, (max − min, RMS) of the 1-s mean of the corrected rate.
type Metrics = [(f64, f64); 3];

/// One activation's metrics with the paper's model and with the extended one.
type BeforeAfter = (Metrics, Metrics);

/// Per axis, (max − min, RMS) of the 1-s mean of the corrected rate.
fn metric(rates: &[Vec<f32>; 3], window: usize) -> Metrics {
    let (drift, rms) = evaluate::metric(rates, window);
    std::array::from_fn(|a| (drift[a], rms[a]))
}

/// Fits the extended model of one unit and writes its tables and the before/after table.
/// Returns the Markdown section.
pub fn run(
    unit: &str,
    axes: &[AxisDiagnosis; 3],
    base: &FittedUnit,
    roles: &Roles<'_>,
    settings: &FitSettings,
    out: &Path,
) -> anyhow::Result<String> {
    let Roles {
        calibration,
        training,
        held_out,
        ..
    } = roles;
    let mut md = format!("## Extended model of unit {unit}\n\n");
    let plan = TermPlan::choose(axes);
    if plan.terms.is_empty() {
        md.push_str("Nothing significant maps to a term the firmware can compute: the paper's model is kept unchanged.\n\n");
        return Ok(md);
    }
    if training.is_empty() {
        let _ = writeln!(
            md,
            "Chosen terms: {}. Their coefficients need field-like activations at the calibration set points (other off-times, supply voltages, orientations: where the terms' inputs vary apart from the table's) and this campaign has none: record some (`gyrodrift simulate --field`) and run again.\n",
            plan.terms.iter().map(|t| t.candidate.as_str()).collect::<Vec<_>>().join(", ")
        );
        return Ok(md);
    }
    let Extended {
        tables,
        plan,
        admissions,
        ..
    } = extend(base, &plan, calibration, training, settings)?;
    let _ = writeln!(
        md,
        "Guard: each proposed term is admitted on an axis only if the refitted model with it (coefficients and tables fitted without the held-out fold) lowers the residual on held-out activations among the {} field-like activations at the calibration set points within the calibrated ambient range (5-fold cross-validation by activation, against the terms admitted before it; one-sided test, Bonferroni over every term and axis, family-wise 5 %):\n",
        training.len()
    );
    md.push_str(
        "| term | axis | held-out gain, (°/s)² | p | admitted |\n|---|---|---:|---:|:---:|\n",
    );
    for a in &admissions {
        let _ = writeln!(
            md,
            "| {} | {} | {:.2e} | {:.3} | {} |",
            a.candidate,
            a.axis,
            a.improvement,
            a.p_value,
            if a.admitted { "yes" } else { "no" }
        );
    }
    md.push('\n');
    if plan.terms.is_empty() {
        md.push_str("No term lowers the held-out error: the paper's model is kept unchanged.\n\n");
        return Ok(md);
    }
    let _ = writeln!(
        md,
        "Terms (coefficients fitted on the {} field-like activations against what the paper's tables leave of each term, tables refitted once on {} calibration activations with the terms' contribution removed):\n",
        training.len(),
        calibration.len()
    );
    md.push_str("| term | from candidate | centre X, Y, Z | coefficient X, Y, Z (°/s per unit) |\n|---|---|---|---|\n");
    for (term, chosen) in tables.extension.terms.iter().zip(&plan.terms) {
        let _ = writeln!(
            md,
            "| {:?} | {} | {:.4}, {:.4}, {:.4} | {:.3e}, {:.3e}, {:.3e} |",
            term.term,
            chosen.candidate,
            term.centre[0],
            term.centre[1],
            term.centre[2],
            term.coefficient[0],
            term.coefficient[1],
            term.coefficient[2]
        );
    }
    if !plan.aux_inputs.is_empty() {
        let _ = writeln!(
            md,
            "\nThe firmware passes these recorded channels as auxiliary inputs 0.., in order: {}.",
            plan.aux_inputs.join(", ")
        );
    }

    // Before/after on the held-out activations, per set point and axis.
    let window = settings.lowpass_window_samples;
    let mut by_set_point: BTreeMap<String, Vec<BeforeAfter>> = BTreeMap::new();
    for segment in held_out {
        let on = switch_on_raw(segment, settings);
        let before = metric(
            &correct_with_terms(&base.modified, &plan, segment, on),
            window,
        );
        let after = metric(&correct_with_terms(&tables, &plan, segment, on), window);
        let key = format!(
            "{:+.1} °C {}",
            segment.labels.set_point_celsius,
            segment.labels.series_kind.as_str()
        );
        by_set_point.entry(key).or_default().push((before, after));
    }
    md.push_str("\n| set point | axis | activations | RMS before | RMS after | drift before | drift after |\n|---|---|---:|---:|---:|---:|---:|\n");
    for (key, results) in &by_set_point {
        for (a, axis) in ["X", "Y", "Z"].iter().enumerate() {
            let n = results.len() as f64;
            let mean = |f: &dyn Fn(&BeforeAfter) -> f64| results.iter().map(f).sum::<f64>() / n;
            let _ = writeln!(
                md,
                "| {key} | {axis} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
                results.len(),
                mean(&|r| r.0[a].1),
                mean(&|r| r.1[a].1),
                mean(&|r| r.0[a].0),
                mean(&|r| r.1[a].0),
            );
        }
    }
    md.push_str("\nRMS: of the 1-s mean of the corrected rate (offsets and drift); drift: its max − min per activation (the paper's metric). Compare with the noise floor of `gyrodrift report --noise-floor`.\n\n");

    let mut image = vec![0; blob::encoded_len(&tables)?];
    blob::encode(&tables, &mut image)?;
    write_atomic(&out.join(format!("extended-{unit}.bin")), &image)?;
    write_atomic(
        &out.join(format!("extended-{unit}.json")),
        serde_json::to_string_pretty(&tables)?.as_bytes(),
    )?;
    let _ = writeln!(
        md,
        "Firmware image: `extended-{unit}.bin` ({} bytes, format version {}); tables as JSON: `extended-{unit}.json`.\n",
        image.len(),
        blob::FORMAT_VERSION
    );
    Ok(md)
}
