//! The figures of the paper's kind, for the first unit's X axis at the first calibration set point,
//! and the drift before and after correction on validation data.

use std::collections::BTreeMap;
use std::path::Path;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::summary::Split;
use drift_fit::analyse::Analysed;
use drift_recording::SeriesKind;

use super::input::ReportInput;
use super::plots::{draw, Chart, Series};
use crate::write_atomic;

const AXIS: usize = 0;

/// Mean over repeats of `value(activation)` per (interval, activation number).
fn per_interval(
    activations: &[&Analysed],
    value: impl Fn(&Analysed) -> Option<f64>,
) -> BTreeMap<u32, BTreeMap<i64, f64>> {
    let mut sums: BTreeMap<u32, BTreeMap<i64, (f64, usize)>> = BTreeMap::new();
    for a in activations {
        let (Some(interval), Some(v)) = (a.labels.interval_min, value(a)) else {
            continue;
        };
        let entry = sums
            .entry(a.labels.activation)
            .or_default()
            .entry((interval * 1000.0).round() as i64)
            .or_default();
        entry.0 += v;
        entry.1 += 1;
    }
    sums.into_iter()
        .map(|(act, m)| {
            (
                act,
                m.into_iter().map(|(i, (s, n))| (i, s / n as f64)).collect(),
            )
        })
        .collect()
}

fn k_at(a: &Analysed, seconds: f64) -> Option<f64> {
    let i =
        ((seconds * 1000.0 / f64::from(a.grid_ms)).round() as usize).min(a.len().checked_sub(1)?);
    let rise = f64::from(a.rise_celsius[AXIS][i]);
    (rise.abs() > 1e-3).then(|| f64::from(a.drift_dps[AXIS][i]) / rise)
}

/// Writes every figure; returns (file name, caption) pairs.
pub fn write_all(dir: &Path, input: &ReportInput<'_>) -> anyhow::Result<Vec<(String, String)>> {
    let mut out = Vec::new();
    let mut save = |name: &str,
                    caption: String,
                    chart: Chart<'_>,
                    series: Vec<Series>|
     -> anyhow::Result<()> {
        if series.iter().all(|s| s.points.is_empty()) {
            return Ok(());
        }
        let svg = draw(&chart, &series)?;
        write_atomic(&dir.join(name), svg.as_bytes())?;
        out.push((name.to_owned(), caption));
        Ok(())
    };
    let Some(unit) = input.fitted.first() else {
        return Ok(out);
    };
    let set_point = unit
        .set_points
        .first()
        .map_or(f64::NAN, |sp| sp.set_point_celsius);
    let activations: Vec<&Analysed> = input
        .calibration
        .iter()
        .filter(|a| {
            a.labels.unit_id == unit.unit_id
                && a.labels.series_kind == SeriesKind::Protocol
                && (a.labels.set_point_celsius - set_point).abs() < 1e-6
        })
        .collect();
    let where_ = format!("{}, axis X, {set_point:+} °C", unit.unit_id);

    let by_activation = |value: &dyn Fn(&Analysed) -> Option<f64>| -> Vec<Series> {
        per_interval(&activations, value)
            .into_iter()
            .map(|(act, points)| {
                Series::line(
                    format!("activation {act}"),
                    points
                        .into_iter()
                        .map(|(i, v)| (i as f64 / 1000.0, v))
                        .collect(),
                )
            })
            .collect()
    };
    save(
        "fig-rise-per-interval.svg",
        format!("Temperature rise after 2 min per activation number against the off-time between activations ({where_}); cf. the paper's Fig. 3a"),
        Chart { title: "Temperature rise at the end of each activation", x: "off-time between activations, min", y: "temperature rise since switch-on, °C" },
        by_activation(&|a| a.rise_celsius[AXIS].last().map(|&v| f64::from(v))),
    )?;
    save(
        "fig-drift-per-interval.svg",
        format!("Drift after 2 min per activation number against the off-time ({where_}); cf. the paper's Fig. 3b"),
        Chart { title: "Drift at the end of each activation", x: "off-time between activations, min", y: "bias drift since switch-on, °/s" },
        by_activation(&|a| a.drift_dps[AXIS].last().map(|&v| f64::from(v))),
    )?;

    // Correlation curves of the shortest interval's activations (the paper's Fig. 4).
    let shortest = activations
        .iter()
        .filter_map(|a| a.labels.interval_min)
        .fold(f64::INFINITY, f64::min);
    let mut curves: BTreeMap<u32, Vec<&Analysed>> = BTreeMap::new();
    for a in activations
        .iter()
        .filter(|a| a.labels.interval_min == Some(shortest))
    {
        curves.entry(a.labels.activation).or_default().push(a);
    }
    let series: Vec<Series> = curves
        .iter()
        .map(|(act, members)| {
            let len = members.iter().map(|m| m.len()).min().unwrap_or(0);
            let step = (500 / members[0].grid_ms.max(1)) as usize;
            let points = (0..len)
                .step_by(step.max(1))
                .filter_map(|i| {
                    let t = members[0].time_s(i);
                    let ks: Vec<f64> = members.iter().filter_map(|m| k_at(m, t)).collect();
                    (t >= 2.0 && !ks.is_empty())
                        .then(|| (t, ks.iter().sum::<f64>() / ks.len() as f64))
                })
                .collect();
            Series::line(format!("activation {act}"), points)
        })
        .collect();
    save(
        "fig-correlation.svg",
        format!("Correlation k = drift / rise after switch-on, activations of the {shortest}-min series ({where_}); cf. the paper's Fig. 4"),
        Chart { title: "Correlation curves", x: "time since switch-on, s", y: "correlation k = drift ÷ rise, (°/s)/°C" },
        series,
    )?;

    // k at fixed times against interval, 5th activation (the paper's Fig. 5).
    let fifth: Vec<&Analysed> = activations
        .iter()
        .copied()
        .filter(|a| a.labels.activation == 5)
        .collect();
    let series: Vec<Series> = [2.0, 5.0, 30.0, 60.0, 119.0]
        .iter()
        .map(|&t| {
            let points = per_interval(&fifth, |a| k_at(a, t))
                .into_values()
                .flat_map(|m| m.into_iter())
                .map(|(i, v)| (i as f64 / 1000.0, v))
                .collect();
            Series::line(format!("{t} s"), points)
        })
        .collect();
    save(
        "fig-k-per-interval.svg",
        format!("k at 2, 5, 30, 60 and 119 s after switch-on against the off-time, 5th activation ({where_}); cf. the paper's Fig. 5"),
        Chart { title: "Correlation at fixed times, 5th activation", x: "off-time between activations, min", y: "correlation k = drift ÷ rise, (°/s)/°C" },
        series,
    )?;

    // Drift before and after, validation activations of the first unit, X.
    let validation: Vec<_> = input
        .results
        .iter()
        .filter(|(s, r)| *s == Split::Validation && r.labels.unit_id == unit.unit_id)
        .collect();
    let series: Vec<Series> = [
        ModelKind::Uncorrected,
        ModelKind::Standard,
        ModelKind::ThirdOrder,
        ModelKind::Relative,
        ModelKind::RelativeCubic,
        ModelKind::Modified,
    ]
    .iter()
    .map(|&model| {
        let points = validation
            .iter()
            .enumerate()
            .filter_map(|(i, (_, r))| {
                r.models
                    .iter()
                    .find(|m| m.model == model)
                    .map(|m| ((i + 1) as f64, m.drift_dps[AXIS]))
            })
            .collect();
        Series::markers(model.name(), points)
    })
    .collect();
    save(
        "fig-drift-before-after.svg",
        format!(
            "Drift of every validation activation of {}, axis X, before and after correction",
            unit.unit_id
        ),
        Chart {
            title: "Drift per validation activation",
            x: "validation activation (from 1, in recording order)",
            y: "drift (max − min within the activation), °/s",
        },
        series,
    )?;
    Ok(out)
}
