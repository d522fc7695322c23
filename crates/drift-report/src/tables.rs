//! The report's tables, in Markdown.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::summary::{AbsoluteCell, Record, Split, WORSE_THAN_BASELINE};
use drift_fit::FittedUnit;

const AXES: [&str; 3] = ["X", "Y", "Z"];
const MODELS: [&str; 8] = [
    "standard",
    "modified",
    "by-history",
    "3rd-order",
    "relative",
    "relative-cubic",
    "recommended",
    "uncorrected",
];

/// The standard baseline with the smallest mean drift on a row's held-out data, and that drift.
fn best_baseline(drift_of: impl Fn(&'static str) -> Option<f64>) -> Option<(&'static str, f64)> {
    ModelKind::BASELINES
        .iter()
        .filter_map(|b| drift_of(b.name()).map(|d| (b.name(), d)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

fn find<'a>(
    records: &'a [Record],
    unit: &str,
    set_point: f64,
    split: Split,
    model: &str,
    axis: &str,
) -> Option<&'a Record> {
    records.iter().find(|r| {
        r.unit == unit
            && (r.set_point_celsius - set_point).abs() < 1e-6
            && r.split == split
            && r.model == model
            && r.axis == axis
    })
}

/// Records of one split, for convenience.
fn of_split(records: &[Record], split: Split) -> impl Iterator<Item = &Record> {
    records.iter().filter(move |r| r.split == split)
}

/// Set points present in a split, ascending.
fn set_points(records: &[Record], split: Split) -> Vec<f64> {
    let milli: BTreeSet<i64> = of_split(records, split)
        .map(|r| (r.set_point_celsius * 1000.0).round() as i64)
        .collect();
    milli.into_iter().map(|m| m as f64 / 1000.0).collect()
}

/// Mean drift of a model over every unit and axis at a set point and split.
fn mean_drift(
    records: &[Record],
    units: &[&FittedUnit],
    set_point: f64,
    split: Split,
    model: &str,
) -> Option<f64> {
    let values: Vec<f64> = units
        .iter()
        .flat_map(|u| {
            AXES.iter()
                .filter_map(move |a| find(records, &u.unit_id, set_point, split, model, a))
        })
        .map(|r| r.drift_dps)
        .collect();
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

fn fitted_units(fitted: &[FittedUnit]) -> Vec<&FittedUnit> {
    fitted.iter().collect()
}

/// Rows (set point, split) of the paper's table: validation set points and the held-out repeats at
/// calibration set points.
fn rows(records: &[Record]) -> Vec<(f64, Split)> {
    let mut rows: Vec<(f64, Split)> = set_points(records, Split::HeldOutRepeat)
        .into_iter()
        .map(|s| (s, Split::HeldOutRepeat))
        .collect();
    rows.extend(
        set_points(records, Split::Validation)
            .into_iter()
            .map(|s| (s, Split::Validation)),
    );
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    rows
}

/// The result in two sentences, with its ratios and the noise floor beside it.
pub fn headline(records: &[Record], fitted: &[FittedUnit], noise_units: &[String]) -> String {
    let units = fitted_units(fitted);
    let mut md = String::from("## Result\n\n");
    md.push_str("Mean drift (max − min of the 1-s low-frequency component over each 2-min activation) over ");
    let _ = writeln!(
        md,
        "{} × 3 axes, on activations the fit did not see:\n",
        count(units.len(), "unit", "units")
    );
    md.push_str("| set point | data | uncorrected | standard | 3rd-order | relative | relative cubic | modified | best baseline / modified | modified, keyed by history | recommended | noise floor |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (set_point, split) in rows(records) {
        let m = |model| mean_drift(records, &units, set_point, split, model);
        let noise: Vec<f64> = noise_units
            .iter()
            .flat_map(|u| {
                AXES.iter().filter_map(move |a| {
                    find(records, u, set_point, Split::NoiseFloor, "uncorrected", a)
                })
            })
            .map(|r| r.drift_dps)
            .collect();
        let noise = (!noise.is_empty()).then(|| noise.iter().sum::<f64>() / noise.len() as f64);
        let fmt = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.4}"));
        let ratio = match (best_baseline(m), m("modified")) {
            (Some((name, s)), Some(d)) if d > 0.0 => format!("**{:.2}×** ({name})", s / d),
            _ => "–".into(),
        };
        let _ = writeln!(
            md,
            "| {set_point:+} °C | {} | {} | {} | {} | {} | {} | {} | {ratio} | {} | {} | {} |",
            split.name(),
            fmt(m("uncorrected")),
            fmt(m("standard")),
            fmt(m("3rd-order")),
            fmt(m("relative")),
            fmt(m("relative-cubic")),
            fmt(m("modified")),
            fmt(m("by-history")),
            fmt(m("recommended")),
            fmt(noise)
        );
    }
    md.push_str("\nAll drifts in °/s. The standard baselines: *standard*, the paper's (Lagrange through the calibration set points, bias = p(T)); *3rd-order*, the PX4/ArduPilot practice (least squares, bias = p(T)); *relative*, least squares relative to the switch-on (bias = q(T_on) + p(T) − p(T_on): the turn-on bias registered at switch-on from the calibration, as the paper's model takes its initial bias, and the drift after it; orders up to the cubic chosen by cross-validation that leaves out one 2.5 °C temperature band of the calibration at a time, so that an order is judged on temperatures it was not fitted at, as between set points); *relative cubic*, the same form with both polynomials cubic, the order PX4 and ArduPilot use. *Best baseline / modified*: against the strongest of the four, the baseline with the smallest drift on the row's own held-out data, named. *Noise floor*: the same metric on a unit with zero systematic drift (uncorrected): no correction can go below it. *Keyed by history*: the paper's curves with stage 3 looked up by the residual heat at switch-on instead of by the rise, each activation started from what firmware kept of the one before in its recording (`by_history.bin`; docs/closed-loop.md). *Recommended*: the paper's drift correction with the turn-on bias fitted on every calibration activation, q(T_on) + h · residual heat, started from what firmware kept (`recommended.bin`; docs/method.md).\n\n");
    md
}

/// The paper's Table: rows model × set point, columns unit × axis.
pub fn paper_table(records: &[Record], fitted: &[FittedUnit]) -> String {
    let units = fitted_units(fitted);
    let mut md = String::from(
        "## Drift per unit and axis (the paper's Table)\n\n| calibration | set point | data |",
    );
    for (i, u) in units.iter().enumerate() {
        for axis in AXES {
            let _ = write!(md, " GIU {} ({}) {axis} |", i + 1, u.unit_id);
        }
    }
    md.push_str("\n|---|---|---|");
    md.push_str(&"---:|".repeat(units.len() * 3));
    md.push('\n');
    for model in MODELS {
        for (set_point, split) in rows(records) {
            let _ = write!(md, "| {model} | {set_point:+} °C | {} |", split.name());
            for u in &units {
                for axis in AXES {
                    match find(records, &u.unit_id, set_point, split, model, axis) {
                        Some(r) => {
                            let _ = write!(md, " {:.4} |", r.drift_dps);
                        }
                        None => md.push_str(" – |"),
                    }
                }
            }
            md.push('\n');
        }
    }
    for (set_point, split) in rows(records) {
        let _ = write!(
            md,
            "| best baseline / modified | {set_point:+} °C | {} |",
            split.name()
        );
        for u in &units {
            for axis in AXES {
                let drift_of = |model| {
                    find(records, &u.unit_id, set_point, split, model, axis).map(|r| r.drift_dps)
                };
                match (best_baseline(drift_of), drift_of("modified")) {
                    (Some((name, s)), Some(d)) if d > 0.0 => {
                        let _ = write!(md, " {:.2}× ({name}) |", s / d);
                    }
                    _ => md.push_str(" – |"),
                }
            }
        }
        md.push('\n');
    }
    md.push_str("\n°/s. ");
    md.push_str(&validation_note(records));
    md.push_str(" Calibration set points: each repeat is left out in turn, the tables refitted on the other repeats, and evaluated on the left-out one.\n\n");
    md
}

/// `n` with the noun in its number: "1 unit", "2 units".
fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Which rows are validation: the set points that have validation results, as the data say.
fn validation_note(records: &[Record]) -> String {
    let validation: Vec<String> = set_points(records, Split::Validation)
        .iter()
        .map(|s| format!("{s:+} °C"))
        .collect();
    match validation.len() {
        0 => "No validation set point had data: every row is a held-out repeat.".into(),
        1 => format!(
            "{}: validation set point, never used in the fit.",
            validation[0]
        ),
        _ => format!(
            "{}: validation set points, never used in the fit.",
            validation.join(", ")
        ),
    }
}

/// Field-like use: off-times and ambients the calibration never had.
pub fn field_table(records: &[Record], fitted: &[FittedUnit]) -> String {
    let units = fitted_units(fitted);
    if of_split(records, Split::Field).next().is_none() {
        return String::new();
    }
    let mut md = String::from("## Field-like use\n\nActivations with random off-times, ambient ramps, supply and orientation changes (never used in the fit), mean over set points. A session's activations count under its nominal set point (the recording's), not under the ambient at switch-on, which ramps and jumps in the field.\n\n| model |");
    for (i, _) in units.iter().enumerate() {
        for axis in AXES {
            let _ = write!(md, " GIU {} {axis} |", i + 1);
        }
    }
    md.push_str(" mean |\n|---|");
    md.push_str(&"---:|".repeat(units.len() * 3 + 1));
    md.push('\n');
    for model in MODELS {
        let _ = write!(md, "| {model} |");
        let (cells, mean) = field_means(records, &units, model);
        for cell in cells {
            match cell {
                Some(v) => {
                    let _ = write!(md, " {v:.4} |");
                }
                None => md.push_str(" – |"),
            }
        }
        let _ = writeln!(md, " {:.4} |", mean.unwrap_or(f64::NAN));
    }
    md.push('\n');
    md
}

/// A model's mean drift on the field-like activations per unit × axis (in column order), and
/// the mean of those.
fn field_means(
    records: &[Record],
    units: &[&FittedUnit],
    model: &str,
) -> (Vec<Option<f64>>, Option<f64>) {
    let cells: Vec<Option<f64>> = units
        .iter()
        .flat_map(|u| AXES.iter().map(move |axis| (u, axis)))
        .map(|(u, axis)| {
            let values: Vec<f64> = of_split(records, Split::Field)
                .filter(|r| r.unit == u.unit_id && r.model == model && r.axis == *axis)
                .map(|r| r.drift_dps)
                .collect();
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        })
        .collect();
    let present: Vec<f64> = cells.iter().flatten().copied().collect();
    let mean = (!present.is_empty()).then(|| present.iter().sum::<f64>() / present.len() as f64);
    (cells, mean)
}

/// The field-like results in one sentence (the means of *Field-like use*): uncorrected, the best
/// standard baseline, the paper's model and the recommended one; `None` without field data.
pub fn field_headline(records: &[Record], fitted: &[FittedUnit]) -> Option<String> {
    of_split(records, Split::Field).next()?;
    let units = fitted_units(fitted);
    let mean = |model: &str| field_means(records, &units, model).1;
    let fmt = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.4}"));
    let best = best_baseline(mean).map_or("–".into(), |(name, d)| format!("{d:.4} ({name})"));
    Some(format!(
        "Field-like use (never fitted), mean drift, °/s: uncorrected {}, best baseline {best}, modified {}, recommended {}",
        fmt(mean("uncorrected")),
        fmt(mean("modified")),
        fmt(mean("recommended"))
    ))
}

/// The noise-floor unit's figures.
pub fn noise_floor(records: &[Record], noise_units: &[String]) -> String {
    if noise_units.is_empty() {
        return String::new();
    }
    let mut md = String::from("## Noise floor\n\nA unit whose systematic drift is zero (same heating and noise): the drift metric of its raw output is what white noise and bias instability alone produce over 2 min with a 1-s window. Its own fitted tables should not add to it. Measured on every activation of its recordings at the validation set points (the nominal one for a field session, whatever the ambient at switch-on).\n\n| unit | set point | model | X | Y | Z |\n|---|---|---|---:|---:|---:|\n");
    for unit in noise_units {
        for set_point in set_points(records, Split::NoiseFloor) {
            for model in ["uncorrected", "modified"] {
                let _ = write!(md, "| {unit} | {set_point:+} °C | {model} |");
                for axis in AXES {
                    match find(records, unit, set_point, Split::NoiseFloor, model, axis) {
                        Some(r) => {
                            let _ = write!(md, " {:.4} |", r.drift_dps);
                        }
                        None => md.push_str(" – |"),
                    }
                }
                md.push('\n');
            }
        }
    }
    md.push('\n');
    md
}

/// Residual bias RMS: includes the initial-bias error that the drift metric ignores.
pub fn residual_rms(records: &[Record], fitted: &[FittedUnit]) -> String {
    let units = fitted_units(fitted);
    let mut md = String::from("## Residual bias RMS\n\nRMS of the corrected low-frequency rate (true rate is zero), mean over axes, °/s. Unlike the drift it includes the error of the initial (switch-on) bias, which turn-on repeatability limits.\n\n| set point | data | model |");
    for u in &units {
        let _ = write!(md, " {} |", u.unit_id);
    }
    md.push_str("\n|---|---|---|");
    md.push_str(&"---:|".repeat(units.len()));
    md.push('\n');
    for (set_point, split) in rows(records) {
        for model in [
            "standard",
            "3rd-order",
            "relative",
            "relative-cubic",
            "modified",
            "recommended",
        ] {
            let _ = write!(md, "| {set_point:+} °C | {} | {model} |", split.name());
            for u in &units {
                let values: Vec<f64> = AXES
                    .iter()
                    .filter_map(|a| find(records, &u.unit_id, set_point, split, model, a))
                    .map(|r| r.residual_rms_dps)
                    .collect();
                if values.is_empty() {
                    md.push_str(" – |");
                } else {
                    let _ = write!(
                        md,
                        " {:.4} |",
                        values.iter().sum::<f64>() / values.len() as f64
                    );
                }
            }
            md.push('\n');
        }
    }
    md.push('\n');
    md
}

/// The absolute-error verdict in one sentence: in how many unit × axis × set point ×
/// activation-class cells the paper's model leaves more than [`WORSE_THAN_BASELINE`] × the best
/// standard baseline's residual bias RMS.
pub fn absolute_error_verdict(cells: &[AbsoluteCell]) -> String {
    let worse = cells.iter().filter(|c| c.worse).count();
    if cells.is_empty() {
        "No held-out activations: no absolute error to compare".to_owned()
    } else if worse == 0 {
        format!(
            "In none of the {} unit × axis × set point × activation-class cells does the paper's model leave more than {WORSE_THAN_BASELINE}× the best standard baseline's residual bias RMS",
            cells.len()
        )
    } else {
        format!(
            "In {worse} of {} unit × axis × set point × activation-class cells the paper's model leaves more than {WORSE_THAN_BASELINE}× the best standard baseline's residual bias RMS",
            cells.len()
        )
    }
}

/// The cells where the paper's model leaves more than [`WORSE_THAN_BASELINE`] × the best
/// baseline's residual bias RMS, for the report's first page: a sentence and a short table, or a
/// sentence saying there are none.
pub fn absolute_error_flags(cells: &[AbsoluteCell]) -> String {
    let mut md = String::from("## Absolute error: where the paper's model is worse\n\n");
    if cells.is_empty() {
        md.push_str("No held-out activations: nothing to compare.\n\n");
        return md;
    }
    let verdict = absolute_error_verdict(cells);
    let worse: Vec<&AbsoluteCell> = cells.iter().filter(|c| c.worse).collect();
    if worse.is_empty() {
        let _ = writeln!(md, "{verdict} (table: *Absolute error*, below).\n");
        return md;
    }
    let _ = writeln!(
        md,
        "**{verdict}** (the drift metric, max − min, does not see a wrong offset; this does). Residual bias RMS, mean over the cell's activations, °/s:\n"
    );
    md.push_str("| unit | axis | set point | activations | n | modified | best baseline | modified / best | why (when known) |\n|---|---|---|---|---:|---:|---|---:|---|\n");
    for c in worse {
        let best = c.baselines.iter().find(|b| b.model == c.best_baseline);
        let why = if c.modified.outside_envelope > 0 {
            format!(
                "{} of {} switched on outside the calibrated ambients (the model clamps to the nearest)",
                c.modified.outside_envelope, c.activations
            )
        } else {
            "–".to_owned()
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:+} °C | {} | {} | {:.4} | {} {:.4} | {:.2}× | {why} |",
            c.unit,
            c.axis,
            c.set_point_celsius,
            c.class.name(),
            c.activations,
            c.modified.mean_dps,
            c.best_baseline,
            best.map_or(f64::NAN, |b| b.mean_dps),
            c.ratio
        );
    }
    md.push('\n');
    md
}

/// The residual bias RMS per activation class, means over its unit × axis × set point cells: the
/// paper's model, its history-keyed form, the recommended model and the best baseline, with the
/// cells where each is worse than the best baseline.
pub fn absolute_error_by_class(cells: &[AbsoluteCell]) -> String {
    if cells.is_empty() {
        return String::new();
    }
    let mut md = String::from("## Absolute error by activation class\n\nResidual bias RMS, means over the class's unit × axis × set point cells, °/s (each cell a mean over its activations; the cells: *Absolute error*, below). *Recommended ≤ best*: the cells where the recommended model leaves no more than the best baseline of that cell.\n\n| class | cells | modified | keyed by history | recommended | best baseline | noise floor | modified > 1.25× best | recommended ≤ best |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let mut classes: Vec<_> = cells.iter().map(|c| c.class).collect();
    classes.sort();
    classes.dedup();
    for class in classes {
        let members: Vec<&AbsoluteCell> = cells.iter().filter(|c| c.class == class).collect();
        let n = members.len() as f64;
        let mean = |f: &dyn Fn(&AbsoluteCell) -> f64| members.iter().map(|c| f(c)).sum::<f64>() / n;
        let best = |c: &AbsoluteCell| {
            c.baselines
                .iter()
                .map(|b| b.mean_dps)
                .fold(f64::INFINITY, f64::min)
        };
        let floor = mean(&|c| c.noise_floor_dps);
        let _ = writeln!(
            md,
            "| {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {} | {} | {} of {} |",
            class.name(),
            members.len(),
            mean(&|c| c.modified.mean_dps),
            mean(&|c| c.by_history.mean_dps),
            mean(&|c| c.recommended.mean_dps),
            mean(&best),
            if floor.is_finite() {
                format!("{floor:.4}")
            } else {
                "–".to_owned()
            },
            members.iter().filter(|c| c.worse).count(),
            members
                .iter()
                .filter(|c| c.recommended_ratio <= 1.0)
                .count(),
            members.len(),
        );
    }
    md.push('\n');
    md
}

/// Residual bias RMS per unit × axis × set point × activation class, with its worst activation
/// and the noise floor.
pub fn absolute_error(cells: &[AbsoluteCell]) -> String {
    if cells.is_empty() {
        return String::new();
    }
    let mut md = String::from("## Absolute error\n\nResidual bias RMS (RMS of the corrected 1-s low-frequency rate; the unit is static, so the true rate is zero) per unit × axis × set point × activation class, on held-out activations, °/s: mean over the class's activations, and its worst activation. Unlike the drift it includes the error of the offset at switch-on. *Cold start*: off at least the calibration's cool-down before it (or first in its series); *warm restart*: off less (residual heat at switch-on); *field*: field-like sessions. *By-history*: the paper's curves keyed by history, started from what firmware kept of the previous activation (mean). *Noise floor*: what the paper's model leaves on the zero-drift unit's activations of the class (turn-on repeatability and noise). Flagged (**bold ratio**) where the paper's model leaves more than 1.25× the best baseline; `outside` counts activations switched on outside the model's calibrated envelope (clamped). The same as data: `absolute_error.json`.\n\n| unit | axis | set point | activations | n | modified (worst, where) | outside | by-history | recommended | standard | 3rd-order | relative | relative cubic | best | modified / best | recommended / best | noise floor |\n|---|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n");
    for c in cells {
        let baseline = |name: &str| {
            c.baselines
                .iter()
                .find(|b| b.model == name)
                .map_or("–".to_owned(), |b| format!("{:.4}", b.mean_dps))
        };
        let ratio = if c.worse {
            format!("**{:.2}×**", c.ratio)
        } else {
            format!("{:.2}×", c.ratio)
        };
        let floor = if c.noise_floor_dps.is_finite() {
            format!("{:.4}", c.noise_floor_dps)
        } else {
            "–".to_owned()
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:+} °C | {} | {} | {:.4} ({:.4}, {}) | {} | {:.4} | {:.4} | {} | {} | {} | {} | {} | {ratio} | {:.2}× | {floor} |",
            c.unit,
            c.axis,
            c.set_point_celsius,
            c.class.name(),
            c.activations,
            c.modified.mean_dps,
            c.modified.worst_dps,
            c.modified.worst_activation,
            c.modified.outside_envelope,
            c.by_history.mean_dps,
            c.recommended.mean_dps,
            baseline("standard"),
            baseline("3rd-order"),
            baseline("relative"),
            baseline("relative-cubic"),
            c.best_baseline,
            c.recommended_ratio,
        );
    }
    md.push('\n');
    md
}

/// Residuals as table cells in 10⁻⁴ °/s, signed ("+12", "-3"); "–" where there is none (NaN).
pub fn ten_thousandths(values: &[f64]) -> Vec<String> {
    values
        .iter()
        .map(|v| {
            if v.is_finite() {
                format!("{:+.0}", v * 1e4)
            } else {
                "–".to_owned()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::ten_thousandths;

    #[test]
    fn residuals_read_in_ten_thousandths_and_a_missing_one_says_so() {
        assert_eq!(
            ten_thousandths(&[0.0012, -0.00004, f64::NAN]),
            ["+12", "-0", "–"]
        );
    }
}
