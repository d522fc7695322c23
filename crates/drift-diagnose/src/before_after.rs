//! The error before and after the extended model on the held-out activations, per group of
//! activations recorded alike (set point and series kind) and axis, beside the noise floor of a
//! zero-drift twin and with the drift excess cut's 95 % interval: what `diagnose --extend` reports,
//! as data (`diagnosis.json`) and as its Markdown table.

use std::collections::BTreeMap;

use drift_evaluate::excess::{excess_cut, ExcessCut};
use drift_evaluate::noise_floor::{group_name, Floor};
use serde::Serialize;

use crate::closing::BeforeAfter;

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// One group × axis of the held-out activations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupError {
    /// The group: set point and series kind (`+33.0 °C field`).
    pub group: String,
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Held-out activations in the group.
    pub activations: usize,
    /// Mean residual bias RMS (of the 1-s mean of the corrected rate), °/s: the paper's model (the
    /// loop's starting model) and the extended one.
    pub rms_before_dps: f64,
    /// The same after the extension, °/s.
    pub rms_after_dps: f64,
    /// Mean drift (max − min of the 1-s mean per activation), °/s, before.
    pub drift_before_dps: f64,
    /// The same after, °/s.
    pub drift_after_dps: f64,
    /// The zero-drift twin's RMS in the same group, °/s (`None` without a twin there).
    pub floor_rms_dps: Option<f64>,
    /// The twin's drift in the same group, °/s.
    pub floor_drift_dps: Option<f64>,
    /// (drift before − floor) / (drift after − floor), with its bootstrap interval.
    pub excess_cut: Option<ExcessCut>,
    /// The extended model drifts more than the starting model with 95 % confidence (the
    /// interval lies wholly below 1×).
    pub worse_with_confidence: bool,
}

/// The held-out activations' results by group (`+33.0 °C field`), in order.
pub fn by_group(results: &[BeforeAfter]) -> BTreeMap<String, Vec<&BeforeAfter>> {
    let mut groups: BTreeMap<String, Vec<&BeforeAfter>> = BTreeMap::new();
    for r in results {
        groups
            .entry(group_name(r.set_point_celsius, r.series_kind))
            .or_default()
            .push(r);
    }
    groups
}

/// Per group and axis, the means before and after beside the floor, and the excess cut.
pub fn group_errors(results: &[BeforeAfter], floor: Option<&Floor>) -> Vec<GroupError> {
    let mut rows = Vec::new();
    for (group, members) in by_group(results) {
        let n = members.len() as f64;
        let at = floor.and_then(|f| f.get(&group));
        for (a, axis) in AXES.into_iter().enumerate() {
            let mean = |f: &dyn Fn(&BeforeAfter) -> f64| members.iter().map(|r| f(r)).sum::<f64>() / n;
            let drift = |after: bool| -> Vec<f64> {
                members
                    .iter()
                    .map(|r| if after { r.drift_dps[a].1 } else { r.drift_dps[a].0 })
                    .collect()
            };
            let cut = at.map(|f| excess_cut(&drift(false), &drift(true), &f.drift[a]));
            rows.push(GroupError {
                group: group.clone(),
                axis,
                activations: members.len(),
                rms_before_dps: mean(&|r| r.rms_dps[a].0),
                rms_after_dps: mean(&|r| r.rms_dps[a].1),
                drift_before_dps: mean(&|r| r.drift_dps[a].0),
                drift_after_dps: mean(&|r| r.drift_dps[a].1),
                floor_rms_dps: at.map(|f| f.mean[a].1),
                floor_drift_dps: at.map(|f| f.mean[a].0),
                worse_with_confidence: cut.is_some_and(|c| c.ratio > 0.0 && c.surely_below(1.0)),
                excess_cut: cut,
            });
        }
    }
    rows
}
