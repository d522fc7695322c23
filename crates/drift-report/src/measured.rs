//! The report for recordings the paper's method cannot be fitted on: why not, and what the data
//! does tell (noise floor, bias per activation, slow drift, a 1-D temperature slope, the residual
//! after a linear temperature correction), from [`drift_evaluate::measured::characterise`].

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use drift_evaluate::measured::{Characterisation, Estimate, Obstacle};

use super::plots;
use crate::write_atomic;

fn pm(e: Option<Estimate>, scale: f64, digits: usize) -> String {
    e.map_or("–".into(), |e| {
        format!(
            "{:+.digits$} ± {:.digits$}",
            e.value * scale,
            e.standard_error * scale
        )
    })
}

/// The Allan deviation at the τ closest to `tau` (within a factor of √2): (τ, σ).
fn adev_at(curve: &[(f64, f64)], tau: f64) -> Option<(f64, f64)> {
    curve
        .iter()
        .filter(|(t, _)| (t / tau).ln().abs() <= std::f64::consts::LN_2 / 2.0 + 1e-9)
        .min_by(|a, b| (a.0 / tau).ln().abs().total_cmp(&(b.0 / tau).ln().abs()))
        .copied()
}

fn unit_section(md: &mut String, c: &Characterisation) -> std::fmt::Result {
    writeln!(
        md,
        "# Unit {}\n\n{} activations, {:.1} s at {} Hz; 1-s mean temperature {:.2} … {:.2} °C ({:.2} °C).\n",
        c.unit_id,
        c.activations.len(),
        c.activations.iter().map(|a| a.duration_s).sum::<f64>(),
        c.sample_rate_hz,
        c.temperature_range_celsius[0],
        c.temperature_range_celsius[1],
        c.temperature_range_celsius[1] - c.temperature_range_celsius[0]
    )?;
    writeln!(md, "## Why the paper's tables are not fitted\n")?;
    if c.obstacles.is_empty() {
        writeln!(md, "Nothing the method needs is missing by these checks.\n")?;
    }
    for o in &c.obstacles {
        writeln!(md, "- {o}")?;
    }
    writeln!(
        md,
        "\nThe tables correlate the drift after switch-on with the temperature rise since switch-on \
         (stage 1: time since switch-on; stage 3: rise), at two or more ambients (stage 2), from \
         series of power cycles with known off-times. Fitting them on this data would fit noise.\n"
    )?;

    writeln!(md, "## Activations\n")?;
    writeln!(md, "| activation | duration, s | temperature mean (min … max), °C | corr(temperature, time) | accelerometer X, Y, Z, g | bias X, °/s | bias Y, °/s | bias Z, °/s |")?;
    writeln!(md, "|---:|---:|---|---:|---|---:|---:|---:|")?;
    for a in &c.activations {
        let t = a.temperature_celsius;
        let accel = a.accel_g.map_or("–".into(), |g| {
            format!("{:+.2}, {:+.2}, {:+.2}", g[0], g[1], g[2])
        });
        writeln!(
            md,
            "| {} | {:.1} | {:.2} ({:.2} … {:.2}) | {:+.2} | {accel} | {:+.4} | {:+.4} | {:+.4} |",
            a.series,
            a.duration_s,
            t[0],
            t[1],
            t[2],
            a.temperature_time_correlation,
            a.axes[0].bias_dps,
            a.axes[1].bias_dps,
            a.axes[2].bias_dps
        )?;
    }

    writeln!(md, "\n## Noise floor\n")?;
    writeln!(md, "Overlapping Allan deviation of the rate on the recording's grid at octave τ (the τ used in brackets), from the longest activation; the minimum is over every activation's curve at τ up to a tenth of the activation, i.e. at least ten independent averages (bias instability ≈ minimum / 0.664). Sample σ and the 1-s mean spread are means over activations. The grid's linear interpolation (resampled data) lowers the deviation at τ of a few samples.\n")?;
    let longest = c
        .activations
        .iter()
        .max_by(|a, b| a.duration_s.total_cmp(&b.duration_s));
    writeln!(md, "| axis | sample σ, °/s | 1-s mean spread, °/s | σ at τ ≈ 0.1 s, °/s | τ ≈ 1 s | τ ≈ 10 s | τ ≈ 100 s | minimum σ, °/s (at τ, s) |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|")?;
    let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len().max(1) as f64;
    for (k, axis) in c.axes.iter().enumerate() {
        let at = |tau: f64| {
            longest
                .and_then(|a| adev_at(&a.axes[k].allan, tau))
                .map_or("–".into(), |(t, v)| format!("{v:.5} ({t:.2} s)"))
        };
        writeln!(
            md,
            "| {} | {:.4} | {:.5} | {} | {} | {} | {} | {} |",
            axis.axis,
            mean(
                c.activations
                    .iter()
                    .map(|a| a.axes[k].sample_std_dps)
                    .collect()
            ),
            mean(
                c.activations
                    .iter()
                    .map(|a| a.axes[k].mean_spread_dps)
                    .collect()
            ),
            at(0.1),
            at(1.0),
            at(10.0),
            at(100.0),
            axis.allan_minimum
                .map_or("–".into(), |(t, v)| format!("{v:.5} ({t:.2})"))
        )?;
    }

    writeln!(md, "\n## Bias per activation and slow drift\n")?;
    writeln!(md, "Slow drift: slope of the 1-s means against time within the activation, ± its OLS standard error (white-noise assumption: an underestimate when the residual is correlated). The paper's drift metric: max − min of the 1-s means over the whole activation.\n")?;
    writeln!(
        md,
        "| activation | slow drift X, °/s per h | Y | Z | drift metric X, °/s | Y | Z |"
    )?;
    writeln!(md, "|---:|---:|---:|---:|---:|---:|---:|")?;
    for a in &c.activations {
        writeln!(
            md,
            "| {} | {} | {} | {} | {:.4} | {:.4} | {:.4} |",
            a.series,
            pm(a.axes[0].slow_drift_dps_per_h, 1.0, 3),
            pm(a.axes[1].slow_drift_dps_per_h, 1.0, 3),
            pm(a.axes[2].slow_drift_dps_per_h, 1.0, 3),
            a.axes[0].drift_dps,
            a.axes[1].drift_dps,
            a.axes[2].drift_dps
        )?;
    }

    writeln!(md, "\n## Bias against temperature (1-D)\n")?;
    writeln!(md, "Within: the 1-s mean rate against the 1-s mean temperature, each activation's own means removed (orientation does not enter), pooled; ± the OLS standard error × √((1 + ρ)/(1 − ρ)) for the residual's lag-1 autocorrelation ρ. Between: activation mean rate against activation mean temperature (orientation and recording day change too).\n")?;
    writeln!(
        md,
        "| axis | within, (°/s)/°C | OLS SE | ρ | between, (°/s)/°C |"
    )?;
    writeln!(md, "|---|---:|---:|---:|---:|")?;
    for axis in &c.axes {
        writeln!(
            md,
            "| {} | {} | {} | {:.2} | {} |",
            axis.axis,
            pm(axis.within_slope, 1.0, 4),
            axis.within_slope_ols_se
                .map_or("–".into(), |v| format!("{v:.4}")),
            axis.residual_lag1,
            pm(axis.between_slope, 1.0, 3)
        )?;
    }
    writeln!(md, "\n## Residual after a linear temperature correction\n")?;
    writeln!(md, "Each activation corrected by slope × (temperature − its mean temperature), the slope fitted on the other activations (leave one out). RMS over every 1-s mean about its activation mean; drift metric averaged over activations.\n")?;
    writeln!(
        md,
        "| axis | RMS before, °/s | RMS after, °/s | drift metric before, °/s | after, °/s |"
    )?;
    writeln!(md, "|---|---:|---:|---:|---:|")?;
    for axis in &c.axes {
        if let Some(r) = axis.correction {
            writeln!(
                md,
                "| {} | {:.5} | {:.5} | {:.4} | {:.4} |",
                axis.axis, r.rms_before_dps, r.rms_after_dps, r.drift_before_dps, r.drift_after_dps
            )?;
        }
    }

    writeln!(md, "\n## What this data cannot tell\n")?;
    let span = c.temperature_range_celsius[1] - c.temperature_range_celsius[0];
    for o in &c.obstacles {
        let text = match o {
            Obstacle::NoWarmUp { .. } => "The drift after switch-on and its correlation with the warm-up (the paper's tables, stage 1 and 3): the recordings start on a warm sensor.".to_owned(),
            Obstacle::OneAmbient { .. } => format!("How the drift depends on the ambient (stage 2): the temperatures span {span:.2} °C in all; a slope over that range says nothing about ±10 °C."),
            Obstacle::NoPowerCycles { .. } => "Anything that depends on the off-time before a switch-on (turn-on repeatability, the heating dynamics of stage 3).".to_owned(),
        };
        writeln!(md, "- {text}")?;
    }
    let strong = c
        .activations
        .iter()
        .filter(|a| a.temperature_time_correlation.abs() > 0.8)
        .count();
    writeln!(
        md,
        "- Temperature from slow drift within an activation: in {strong} of {} activations the 1-s mean temperature correlates with time by more than 0.8 in magnitude, so a within-activation slope is as much a slope against time.",
        c.activations.len()
    )?;
    writeln!(
        md,
        "- Temperature from orientation between activations: each activation has its own orientation (gravity on another axis) and the recordings come from different sessions, so the between-activation slope mixes g-sensitivity and day-to-day bias with temperature.\n"
    )?;
    Ok(())
}

fn allan_figure(c: &Characterisation) -> anyhow::Result<Option<String>> {
    let Some(longest) = c
        .activations
        .iter()
        .max_by(|a, b| a.duration_s.total_cmp(&b.duration_s))
    else {
        return Ok(None);
    };
    let series: Vec<plots::Series> = longest
        .axes
        .iter()
        .zip(["X", "Y", "Z"])
        .map(|(axis, name)| {
            plots::Series::line(
                name,
                axis.allan
                    .iter()
                    .map(|(t, s)| (t.log10(), s.log10()))
                    .collect(),
            )
        })
        .collect();
    let title = format!(
        "Allan deviation, unit {}, activation {} ({:.0} s)",
        c.unit_id, longest.series, longest.duration_s
    );
    Ok(Some(plots::draw(
        &plots::Chart {
            title: &title,
            x: "log10 τ, s",
            y: "log10 σ, °/s",
        },
        &series,
    )?))
}

/// Writes `report.md`, `characterisation.json` and an Allan-deviation figure per unit into `dir`;
/// returns the report's path. `why` is the fit's own message.
pub fn write_measured_report(
    dir: &Path,
    units: &[Characterisation],
    provenance: &[String],
    why: &str,
) -> anyhow::Result<PathBuf> {
    let mut md = String::from(
        "# gyrodrift report: measured data the paper's method cannot be fitted on\n\n",
    );
    for line in provenance {
        writeln!(md, "{line}")?;
    }
    writeln!(md, "\nThe fit stopped at: {why}.\n")?;
    let mut figures = Vec::new();
    for c in units {
        unit_section(&mut md, c)?;
        if let Some(svg) = allan_figure(c)? {
            let file = format!("allan-{}.svg", c.unit_id);
            writeln!(md, "![Allan deviation of unit {}]({file})\n", c.unit_id)?;
            figures.push((file, svg));
        }
    }
    for (file, svg) in &figures {
        write_atomic(&dir.join(file), svg.as_bytes())?;
    }
    write_atomic(
        &dir.join("characterisation.json"),
        serde_json::to_string_pretty(units)?.as_bytes(),
    )?;
    let path = dir.join("report.md");
    write_atomic(&path, md.as_bytes())?;
    Ok(path)
}
