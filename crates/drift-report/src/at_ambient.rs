//! The report's section on the switch-on at a measured ambient: the paper's tables started at the
//! switch-on temperature (the paper's way) beside the same tables started at the ambient a logged
//! channel held at switch-on, both metrics, beside the noise floor.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::summary::{Record, Split};

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The section, or nothing when the at-ambient model was not evaluated. `channel` names where the
/// ambient was read; `noise_units` are the zero-drift twins' unit ids.
pub fn section(records: &[Record], channel: Option<&str>, noise_units: &[String]) -> String {
    let at_ambient = ModelKind::AtAmbient.name();
    let Some(channel) = channel else {
        return String::new();
    };
    if !records.iter().any(|r| r.model == at_ambient) {
        return String::new();
    }
    let paper = ModelKind::Modified.name();
    let mut md = format!(
        "## Switch-on at a measured ambient\n\nThe paper's tables read their ambient (stage 2) and initial bias at the switch-on temperature; *{at_ambient}* reads them at the `{channel}` channel's value at each activation's switch-on, as firmware with an ambient reading does (drift-core's `power_on_at_ambient`); time since switch-on and the rise are read as always. Mean over units, °/s; *floor*: the paper's model on the zero-drift twin at that set point (– without one).\n\n| data | set point | metric | {paper} X | Y | Z | {at_ambient} X | Y | Z | floor X | Y | Z |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    );
    let rows: BTreeSet<(Split, i64)> = records
        .iter()
        .filter(|r| r.model == at_ambient && r.split != Split::NoiseFloor)
        .map(|r| (r.split, (r.set_point_celsius * 1000.0).round() as i64))
        .collect();
    for (split, milli) in rows {
        let set_point = milli as f64 / 1000.0;
        for (metric, value) in [
            ("drift", (|r: &Record| r.drift_dps) as fn(&Record) -> f64),
            ("RMS", |r: &Record| r.residual_rms_dps),
        ] {
            let _ = write!(md, "| {} | {set_point:+} °C | {metric} |", split.name());
            let units = |noise: bool| move |r: &&Record| noise_units.contains(&r.unit) == noise;
            for (model, split, noise) in [
                (paper, split, false),
                (at_ambient, split, false),
                (paper, Split::NoiseFloor, true),
            ] {
                for axis in AXES {
                    let values: Vec<f64> = records
                        .iter()
                        .filter(|r| {
                            r.model == model
                                && r.split == split
                                && r.axis == axis
                                && (r.set_point_celsius - set_point).abs() < 1e-6
                        })
                        .filter(units(noise))
                        .map(value)
                        .collect();
                    if values.is_empty() {
                        md.push_str(" – |");
                    } else {
                        let mean = values.iter().sum::<f64>() / values.len() as f64;
                        let _ = write!(md, " {mean:.4} |");
                    }
                }
            }
            md.push('\n');
        }
    }
    md.push('\n');
    md
}
