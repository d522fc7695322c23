//! The residual against each axis's top candidate, as SVG beside the report.

use std::fmt::Write as _;
use std::path::PathBuf;

use drift_diagnose::diagnose::{ActivationSeries, AxisDiagnosis, CandidateScore};

use crate::plots;

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

/// Adds each axis's plot of the residual against its top candidate (unless the model absorbs
/// it) and returns the report's links to them.
pub(super) fn residual_plots(
    unit: &str,
    activations: &[ActivationSeries],
    axes: &[AxisDiagnosis],
    files: &mut Vec<(PathBuf, Vec<u8>)>,
) -> anyhow::Result<String> {
    let mut md = String::new();
    for (axis_index, axis) in axes.iter().enumerate() {
        if let Some(top) = axis
            .ranking
            .first()
            .filter(|c| c.level != "absorbed by the model")
        {
            let file = format!("residual-{unit}-{}.svg", axis.axis);
            files.push((
                PathBuf::from(&file),
                residual_plot(activations, axis_index, top)?.into_bytes(),
            ));
            let _ = writeln!(
                md,
                "![Residual of unit {unit}, axis {}, against {}]({file})\n",
                axis.axis, top.name
            );
        }
    }
    Ok(md)
}
