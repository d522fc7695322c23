//! The report section of the extended model (`gyrodrift diagnose --extend`)
//! ([`drift_diagnose::closing`]): the guard's decisions, the admitted terms, the error before and after
//! on the held-out activations, and the firmware image.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use drift_core::blob;
use drift_diagnose::before_after::group_errors;
use drift_diagnose::closing::{BeforeAfter, Closed};
use drift_diagnose::switch_on_rate::SwitchOnRateFit;
use drift_evaluate::noise_floor::Floor;
use drift_evaluate::tables_folder::{self, TablesError};
use drift_fit::FittedUnit;

/// The extended model of one unit: its Markdown section, with its image and JSON added to
/// `files`.
pub(super) fn run(
    unit: &str,
    closed: &Closed<'_>,
    fitted: &FittedUnit,
    before_after: &[BeforeAfter],
    floor: Option<&Floor>,
    files: &mut Vec<(PathBuf, Vec<u8>)>,
) -> anyhow::Result<String> {
    let mut md = format!("## Extended model of unit {unit}\n\n");
    md.push_str(&terms_markdown(closed));
    let terms = closed
        .extended
        .as_ref()
        .is_some_and(|e| !e.plan.terms.is_empty());
    if !terms && !closed.keying.any() {
        md.push_str("The paper's model is kept unchanged.\n\n");
        return Ok(md);
    }
    let mut tables = closed.model(fitted);
    // The loop refits on block means: the image states the rate the unit was recorded at.
    tables.settings.sample_rate_hz = fitted.modified.settings.sample_rate_hz;
    let keying = &closed.keying;
    for (what, axes) in [
        ("Stage 3 is keyed by heating history", keying.by_history),
        (
            "The initial bias of warm starts is taken from the calibration's series",
            keying.warm_start,
        ),
    ] {
        let axes: Vec<&str> = ["X", "Y", "Z"]
            .into_iter()
            .zip(axes)
            .filter_map(|(axis, chosen)| chosen.then_some(axis))
            .collect();
        if !axes.is_empty() {
            let _ = writeln!(
                md,
                "{what} on {} (chosen on the training activations, above): firmware running this image starts with `power_on_after` and calls `keep` before power-off.\n",
                axes.join(", ")
            );
        }
    }
    md.push_str(&before_after_table(before_after, floor));
    let stem = format!("extended-{unit}");
    let from = tables_folder::provenance(unit).map_err(|problem| TablesError::Encode {
        path: PathBuf::from(format!("{stem}.bin")),
        problem,
    })?;
    // Named relative to the report's folder, where the report's writer puts them.
    let model = tables_folder::model_files(Path::new(""), &stem, &*tables, &from)?;
    let image_len = model[1].1.len();
    files.extend(model);
    let _ = writeln!(
        md,
        "Firmware image of the loop's model: `extended-{unit}.bin` ({} bytes, format version {}); tables as JSON: `extended-{unit}.json`.\n",
        image_len,
        blob::FORMAT_VERSION
    );
    Ok(md)
}

/// The extended model's outcome for one unit in one console line: what the Markdown section says
/// at length, so nobody has to open the file to learn that nothing was extended, or why.
pub(super) fn verdict(unit: &str, closed: &Closed<'_>) -> String {
    let keyed = closed.keying.any();
    let kept = if keyed {
        "the paper's tables with stage 3 or warm starts keyed by history"
    } else {
        "the paper's model unchanged"
    };
    if closed.proposed.terms.is_empty() {
        return format!("no term proposed (nothing significant maps to a term the firmware can compute); {kept}");
    }
    let proposed = closed
        .proposed
        .terms
        .iter()
        .map(|t| t.candidate.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    let Some(extended) = &closed.extended else {
        return format!(
            "proposed {proposed}, but no field-like activations at the calibration set points to guard and fit them (record some: `gyrodrift simulate --field`); {kept}"
        );
    };
    let admitted: Vec<String> = extended
        .admissions
        .iter()
        .filter(|a| a.admitted)
        .map(|a| format!("{} on {}", a.candidate, a.axis))
        .collect();
    if admitted.is_empty() {
        let reasons: Vec<String> = extended
            .admissions
            .iter()
            .filter(|a| a.reason.starts_with("significant"))
            .map(|a| format!("{} on {}: {}", a.candidate, a.axis, a.reason))
            .collect();
        if reasons.is_empty() {
            format!("proposed {proposed}; none lowers the held-out error; {kept}")
        } else {
            format!(
                "proposed {proposed}; none admitted ({}); {kept}",
                reasons.join("; ")
            )
        }
    } else {
        format!(
            "admitted {} (firmware image `extended-{unit}.bin`)",
            admitted.join(", ")
        )
    }
}

/// The guard's decisions and the admitted terms, as Markdown.
fn terms_markdown(closed: &Closed<'_>) -> String {
    let calibration = &closed.roles.calibration;
    let mut md = String::new();
    if closed.proposed.terms.is_empty() {
        md.push_str("Nothing significant maps to a term the firmware can compute, and the tables absorb every temperature-rate candidate, so there is no element rate to offer.\n\n");
        return md;
    }
    let Some(extended) = &closed.extended else {
        let _ = writeln!(
            md,
            "Proposed terms: {}. Their guard and coefficients need field-like activations at the calibration set points, inside the calibrated ambient range (other off-times, supply voltages, orientations: where the terms' inputs vary apart from the table's), and this campaign has none: record some (`gyrodrift simulate --field`) and run again.\n",
            closed.proposed.terms.iter().map(|t| t.candidate.as_str()).collect::<Vec<_>>().join(", ")
        );
        return md;
    };
    let _ = writeln!(
        md,
        "Guard, on the {} activations the terms are fitted on (field-like activations at the calibration set points within the calibrated ambient range, and this half of the analyst's diagnosis series if any), 5-fold cross-validation by series, the refitted model with the term (coefficients and tables fitted without the held-out fold) against the one without it. On an axis whose diagnosis found the term significant, it is admitted unless the held-out folds say it makes things worse: the metric it is for (the drift for a shape, the squared residual for an offset) must fall on average, the other must not rise significantly (one-sided, 5 %; the drift by more than 1 %). On any other axis it must earn its place: an auxiliary input, which moves offsets between activations, must lower the squared residual, a term that changes the shape within activations (temperature rate, rise², another axis's rise) the drift (one-sided test, Bonferroni over every term and axis, family-wise 5 %), without making the other metric significantly worse.\n",
        closed.roles.fitting().len(),
    );
    md.push_str(
        "| term | axis | held-out gain, (°/s)² | p | held-out drift gain, °/s | p drift | admitted | why |\n|---|---|---:|---:|---:|---:|:---:|---|\n",
    );
    for a in &extended.admissions {
        let _ = writeln!(
            md,
            "| {} | {} | {:.2e} | {:.3} | {:+.2e} | {:.3} | {} | {} |",
            a.candidate,
            a.axis,
            a.improvement,
            a.p_value,
            a.drift_gain_dps,
            a.drift_p_value,
            if a.admitted { "yes" } else { "no" },
            a.reason
        );
    }
    md.push('\n');
    if extended.plan.terms.is_empty() {
        md.push_str("No term lowers the held-out error.\n\n");
        return md;
    }
    let tables = &extended.tables;
    let _ = writeln!(
        md,
        "Terms (coefficients fitted on the {} activations above against what the paper's tables leave of each term, tables refitted once at the drift fit's reference times on {} calibration activations with the terms' contribution removed):\n",
        closed.roles.fitting().len(),
        calibration.len()
    );
    md.push_str("| term | from candidate | centre X, Y, Z | coefficient X, Y, Z (°/s per unit) |\n|---|---|---|---|\n");
    for (term, chosen) in tables.extension.terms.iter().zip(&extended.plan.terms) {
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
    if !extended.plan.aux_inputs.is_empty() {
        let _ = writeln!(
            md,
            "\nThe firmware passes these recorded channels as auxiliary inputs 0.., in order: {}.",
            extended.plan.aux_inputs.join(", ")
        );
    }
    if let Some(element) = extended.plan.element_rate {
        md += &switch_on_rate_markdown(element, &closed.switch_on_rate);
    }
    md
}

/// The switch-on rate section: where the rate filter starts, as measured on the calibration, for
/// the element's rate (`element`: the cooling alone) or the sensor's.
fn switch_on_rate_markdown(element: bool, fits: &[SwitchOnRateFit; 3]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "\nThe rate filter starts at the rate the unit has at switch-on ({}), measured on the calibration activations: heating − residual heat · (cooling + faster · remaining), where remaining is the fraction of the previous switch-off's heat still there (firmware: `power_on_after`; `power_on` starts a cold start's).\n\n| axis | heating, °C/s (cold starts) | cooling, 1/s | faster, 1/s (warm starts) | warm starts' RMS about the fit, °C/s |\n|---|---:|---:|---:|---:|",
        if element {
            "the element's: it has not started heating, so only the cooling, and the heating below is not used"
        } else {
            "the sensor's: its heating less its cooling"
        }
    );
    for fit in fits {
        let _ = writeln!(
            md,
            "| {} | {:.4} ({}) | {:.5} | {:.5} ({}) | {:.1e} |",
            fit.axis,
            fit.rate.heating_celsius_per_s,
            fit.cold_starts,
            fit.rate.cooling_per_second,
            fit.rate.cooling_per_second_per_remaining,
            fit.warm_starts,
            fit.cooling_rms_error_celsius_per_s
        );
    }
    md
}

/// Means per set point, series kind and axis of the held-out activations' errors, with the noise
/// floor of their set point when measured, and then how many times the model cuts the drift in
/// excess of it, with a 95 % interval.
fn before_after_table(results: &[BeforeAfter], floor: Option<&Floor>) -> String {
    let rows = group_errors(results, floor);
    let mut md = String::from("\nError on the held-out activations (nothing was fitted or chosen on them):\n\n| set point | axis | activations | RMS before | RMS after | noise floor RMS | drift before | drift after | noise floor drift | drift excess cut (95 %) |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let shown = |v: Option<f64>| v.map_or_else(|| "–".to_owned(), |v| format!("{v:.4}"));
    for row in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.4} | {:.4} | {} | {:.4} | {:.4} | {} | {} |",
            row.group,
            row.axis,
            row.activations,
            row.rms_before_dps,
            row.rms_after_dps,
            shown(row.floor_rms_dps),
            row.drift_before_dps,
            row.drift_after_dps,
            shown(row.floor_drift_dps),
            row.excess_cut
                .map_or_else(|| "–".to_owned(), |c| c.to_string()),
        );
    }
    let worse: Vec<String> = rows
        .iter()
        .filter(|r| r.worse_with_confidence)
        .map(|r| format!("{} {}", r.group, r.axis))
        .collect();
    md.push_str(if floor.is_some() {
        "\nRMS: of the 1-s mean of the corrected rate (offsets and drift); drift: its max − min per activation (the paper's metric). Noise floor: the zero-drift units of `--noise-floor`, the same set point and series kind, uncorrected, less each unit's constant bias — the physical limit beside each figure; – where the twin has no such activations. Drift excess cut: (drift before − floor) / (drift after − floor) over the activations pooled, with the 2.5–97.5 % range of a bootstrap over the held-out activations and the twin's; – where the drift before is at the floor, or below it.\n\n"
    } else {
        "\nRMS: of the 1-s mean of the corrected rate (offsets and drift); drift: its max − min per activation (the paper's metric). No noise floor given: record a zero-drift twin (`gyrodrift simulate --zero-drift`) and pass it as `--noise-floor`.\n\n"
    });
    if !worse.is_empty() {
        let _ = writeln!(
            md,
            "**The extended model drifts more than the paper's, with 95 % confidence, on: {}.** Where the unit is used like those activations, keep the paper's model.\n",
            worse.join(", ")
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use drift_core::SwitchOnRate;

    fn fit(axis: &'static str, heating: f32, cooling: f32) -> SwitchOnRateFit {
        SwitchOnRateFit {
            axis,
            cold_starts: 36,
            warm_starts: 48,
            rate: SwitchOnRate {
                heating_celsius_per_s: heating,
                cooling_per_second: cooling,
                cooling_per_second_per_remaining: 0.0162,
            },
            cooling_rms_error_celsius_per_s: 0.0021,
        }
    }

    #[test]
    fn the_switch_on_rate_section_has_one_row_per_axis_and_says_which_rate_starts_there() {
        let fits = [
            fit("X", 0.1559, 0.0028),
            fit("Y", 0.1166, 0.0023),
            fit("Z", 0.1703, 0.0007),
        ];
        let element = switch_on_rate_markdown(true, &fits);
        let rows: Vec<&str> = element.lines().filter(|l| l.starts_with("| ")).collect();
        assert_eq!(rows.len(), 4, "{element}"); // the header and one row per axis
        assert_eq!(
            rows[1],
            "| X | 0.1559 (36) | 0.00280 | 0.01620 (48) | 2.1e-3 |"
        );
        assert!(
            rows[3].starts_with("| Z | 0.1703 (36) | 0.00070 |"),
            "{element}"
        );
        assert!(
            element.contains("the element's: it has not started heating"),
            "{element}"
        );
        let sensor = switch_on_rate_markdown(false, &fits);
        assert!(
            sensor.contains("the sensor's: its heating less its cooling")
                && !sensor.contains("the element's"),
            "{sensor}"
        );
    }

    fn held_out(drift_before: f64, drift_after: f64) -> BeforeAfter {
        BeforeAfter {
            set_point_celsius: 33.0,
            series_kind: "field",
            drift_dps: [(drift_before, drift_after); 3],
            rms_dps: [(0.004, 0.003); 3],
            by_history_drift_dps: [drift_before; 3],
            by_history_rms_dps: [0.004; 3],
            mean_dps: [(0.0, 0.0); 3],
            residual_heat_celsius: [0.0; 3],
            off_before_s: Some(600.0),
        }
    }

    #[test]
    fn the_before_after_table_cuts_the_drift_excess_over_the_twins_floor_with_its_interval() {
        // Drift 0.0040 → 0.0025 over a 0.0010 floor: the excess 0.0030 → 0.0015, cut 2.0×.
        let results: Vec<BeforeAfter> = (0..12)
            .map(|i| {
                let wiggle = if i % 2 == 0 { 0.0004 } else { -0.0004 };
                held_out(0.0040 + wiggle, 0.0025 + wiggle / 2.0)
            })
            .collect();
        let floor: Floor = [(
            "+33.0 °C field".to_owned(),
            drift_evaluate::noise_floor::FloorGroup {
                mean: [(0.0010, 0.0030); 3],
                drift: std::array::from_fn(|_| vec![0.0009, 0.0011, 0.0010, 0.0010]),
            },
        )]
        .into_iter()
        .collect();
        let with = before_after_table(&results, Some(&floor));
        assert!(!with.contains("drifts more than the paper's"), "{with}");
        let row = with
            .lines()
            .find(|l| l.starts_with("| +33.0 °C field | Y |"))
            .unwrap_or_default();
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!(cells[9], "0.0010", "{with}");
        assert!(cells[10].starts_with("2.0× ("), "{with}");
        assert!(with.contains("| drift excess cut (95 %) |"), "{with}");
        // A group the model makes worse, with confidence, is named below the table.
        let mut worse = results.clone();
        worse.extend((0..12).map(|i| {
            let wiggle = if i % 2 == 0 { 0.0002 } else { -0.0002 };
            BeforeAfter {
                set_point_celsius: 40.0,
                ..held_out(0.0030 + wiggle, 0.0060 + wiggle)
            }
        }));
        let mut floors = floor.clone();
        floors.insert("+40.0 °C field".to_owned(), floor["+33.0 °C field"].clone());
        let warned = before_after_table(&worse, Some(&floors));
        let warning = warned
            .lines()
            .find(|l| l.contains("drifts more than the paper's"))
            .unwrap_or_default();
        assert!(
            warning.contains("+40.0 °C field X, +40.0 °C field Y, +40.0 °C field Z")
                && !warning.contains("+33.0"),
            "{warned}"
        );
        // Without a twin there is no floor to cut to.
        let without = before_after_table(&results, None);
        assert!(
            without
                .lines()
                .filter(|l| l.starts_with("| +33.0 °C field"))
                .all(|l| l.ends_with("| – | – |")),
            "{without}"
        );
    }
}
