//! The report's σ(t) section: the fitted residual bias's standard deviation after switch-on and
//! how often held-out residuals fell within ±2σ, per class.

use std::fmt::Write as _;

use drift_evaluate::uncertainty::{ActivationClass, Coverage, UnitUncertainty, EVERY_MS, KNOTS_MS};

fn percent(cell: &Coverage) -> String {
    share(cell.inside, cell.samples)
}

fn share(part: usize, whole: usize) -> String {
    if whole == 0 {
        "–".into()
    } else {
        format!("{:.1} %", 100.0 * part as f64 / whole as f64)
    }
}

/// The section (Markdown); empty when no unit has σ(t) (no held-out repeats to fit it on).
pub fn section(units: &[UnitUncertainty]) -> String {
    if units.is_empty() {
        return String::new();
    }
    let mut md = String::new();
    let _ = writeln!(md, "## Residual uncertainty σ(t)\n");
    let _ = writeln!(
        md,
        "σ(t) of the recommended model, for a navigation filter's gyro-bias uncertainty: fitted per \
         unit on the calibration activations corrected by tables fitted without their repeat (half \
         the 95th percentile of the 1-s residual's magnitude per knot and class, every axis), \
         checked on validation and field activations neither saw. Warm restart: residual heat at \
         switch-on above {} °C (what firmware estimates from what it kept). Residuals every {} ms; \
         the goal is 93–97 % within ±2σ. Outside the envelope (switch-on ambient outside the \
         calibration's set points, or residual heat beyond the calibration's most) σ widens; the \
         last three columns split the samples there from those inside.\n",
        drift_evaluate::uncertainty::WARM_ABOVE_CELSIUS,
        EVERY_MS
    );
    let _ = writeln!(
        md,
        "| unit | data | class | activations × axes | samples | within ±2σ | samples outside the envelope | within ±2σ there | within ±2σ inside |\n|---|---|---|---:|---:|---:|---:|---:|---:|"
    );
    for unit in units {
        for split in &unit.coverage {
            for cell in &split.classes {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    unit.unit_id,
                    split.split,
                    cell.class,
                    cell.axis_activations,
                    cell.samples,
                    percent(cell),
                    share(cell.widened_samples, cell.samples),
                    share(cell.widened_inside, cell.widened_samples),
                    share(
                        cell.inside - cell.widened_inside,
                        cell.samples - cell.widened_samples
                    )
                );
            }
        }
    }
    let _ = writeln!(
        md,
        "\nWhat a σ(t) of this form reaches on the held-out data itself, inside the envelope: the \
         oracle fits σ's curves (per class and knot, every axis alike) on the very residuals it is \
         checked on; the split-half oracle fits them on every other activation and checks them on \
         the rest, both ways. The oracle near 95 % says the form is not what misses; the \
         split-half oracle's spread around 95 % is how far a σ fitted on residuals of the very \
         same kind scatters at this many activations.\n"
    );
    let _ = writeln!(
        md,
        "| unit | data | class | activations × axes inside | within ±2σ inside | oracle | split-half oracle |\n|---|---|---|---:|---:|---:|---:|"
    );
    for unit in units {
        for split in &unit.coverage {
            for ((cell, oracle), halves) in split
                .classes
                .iter()
                .zip(&split.oracle)
                .zip(&split.split_half)
            {
                let inside = |c: &Coverage| {
                    share(c.inside - c.widened_inside, c.samples - c.widened_samples)
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} |",
                    unit.unit_id,
                    split.split,
                    cell.class,
                    cell.axis_activations - cell.widened_axis_activations,
                    inside(cell),
                    inside(oracle),
                    inside(halves),
                );
            }
        }
    }
    let header: Vec<String> = KNOTS_MS
        .iter()
        .map(|ms| format!("{} s", f64::from(*ms) / 1000.0))
        .collect();
    let _ = writeln!(
        md,
        "\nσ at the knots, m°/s (linear between them, held after the last; plus the growth per °C \
         of switch-on ambient outside the envelope and per °C of residual heat beyond the \
         calibration's most, per axis X / Y / Z):\n"
    );
    let _ = writeln!(
        md,
        "| unit | class | {} | envelope | outside, m°/s per °C | most residual heat | beyond, m°/s per °C |\n|---|---|{}---|---:|---|---:|",
        header.join(" | "),
        "---:|".repeat(header.len())
    );
    for unit in units {
        let s = &unit.sigma;
        for class in ActivationClass::ALL {
            let values: Vec<String> = s.sigma_dps[class as usize]
                .iter()
                .map(|v| format!("{:.2}", v * 1000.0))
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} | {}–{} °C | {:.3} | {} °C | {:.3} |",
                unit.unit_id,
                class.name(),
                values.join(" | "),
                s.ambient_min_celsius,
                s.ambient_max_celsius,
                s.per_celsius_outside_dps * 1000.0,
                s.most_residual_heat_celsius
                    .map(|h| format!("{h:.2}"))
                    .join(" / "),
                s.per_residual_celsius_beyond_dps * 1000.0
            );
        }
    }
    md.push('\n');
    md
}
