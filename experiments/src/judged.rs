//! The loop's outcome on one world, judged: what it said on each axis (ranking, terms admitted
//! and refused) and the drift of every held-out +33 °C field activation before and after, beside
//! the zero-drift twin's. The blind run and the oracle's are judged by this one function, so their
//! cuts compare.

use std::path::Path;

use drift_diagnose::closing::Closed;
use drift_fit::fit::FittedUnit;
use drift_fit::FitSettings;

use drift_recording::RECORDINGS_DIR;
use serde::{Deserialize, Serialize};

use crate::closed_loop::{is, validation_field_floor, VALIDATION};

/// The axes' names, as the loop's admissions name them.
pub const AXES: [&str; 3] = ["X", "Y", "Z"];

/// One candidate as the loop ranked it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Ranked {
    /// Its name.
    pub name: String,
    /// Significant (family-wise by shuffling, `drift_diagnose::permutation`).
    pub significant: bool,
    /// Its family-wise p-value.
    pub family_p_value: f64,
    /// Out-of-sample share of the residual's variance it explains.
    pub explained: f64,
    /// A term of the unit's own thermal response, fitted before any effect is sought
    /// (`drift_diagnose::candidates::Kind::is_thermal_response`); every other candidate is an
    /// effect.
    #[serde(default)]
    pub thermal_response: bool,
    /// One-sided p-value of the held-out improvement at its level.
    pub p_value: f64,
    /// The same on the whole residual.
    pub whole_p_value: f64,
    /// Same coefficient sign in every fold.
    pub stable: bool,
    /// Coefficient, (°/s) per candidate unit.
    pub coefficient: f64,
}

/// What the loop said on one axis, and what it measured there.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AxisOutcome {
    /// The best candidates behind the loop's model, best first.
    pub ranking: Vec<Ranked>,
    /// Whether any effect on the axis is significant (the unit's own thermal response aside).
    pub any_significant: bool,
    /// The explained share a candidate had to exceed to be significant on this axis.
    pub detectable_share: f64,
    /// Terms the guard admitted on the axis.
    pub admitted: Vec<String>,
    /// Terms the guard left out on the axis, each with its reason.
    #[serde(default)]
    pub refused: Vec<String>,
    /// Drift (max − min of the 1-s mean) of each held-out +33 °C field activation, paper's model,
    /// °/s.
    pub before_dps: Vec<f64>,
    /// The same with the loop's model.
    pub after_dps: Vec<f64>,
    /// The zero-drift twin's +33 °C field activations, uncorrected less its constant bias.
    pub floor_dps: Vec<f64>,
}

/// What the closed loop said on each axis, and the drift of every held-out +33 °C field
/// activation before (the paper's tables, `base`) and after (the loop's model) beside the
/// twin's in `floor_dir` (the noise floor).
pub fn judged_axes(
    base: &FittedUnit,
    closed: &Closed,
    floor_dir: &Path,
    settings: &FitSettings,
) -> anyhow::Result<Vec<AxisOutcome>> {
    let measured: Vec<_> = closed
        .before_after(base, settings)
        .into_iter()
        .filter(|r| r.series_kind == "field" && is(VALIDATION, r.set_point_celsius))
        .collect();
    let floor = validation_field_floor(&floor_dir.join(RECORDINGS_DIR), settings)?;
    let on_axis = |a: usize, admitted: bool| -> Vec<String> {
        closed
            .extended
            .iter()
            .flat_map(|e| &e.admissions)
            .filter(|x| x.axis == AXES[a] && x.admitted == admitted)
            .map(|x| {
                if admitted {
                    x.candidate.clone()
                } else {
                    format!("{}: {}", x.candidate, x.reason)
                }
            })
            .collect()
    };
    Ok((0..3)
        .map(|a| {
            let diagnosis = &closed.axes[a];
            AxisOutcome {
                ranking: diagnosis
                    .ranking
                    .iter()
                    .map(|c| Ranked {
                        name: c.name.clone(),
                        significant: c.significant,
                        family_p_value: c.family_p_value,
                        explained: c.explained,
                        p_value: c.p_value,
                        whole_p_value: c.whole_p_value,
                        stable: c.stable,
                        coefficient: c.coefficient,
                        thermal_response: c.thermal_response,
                    })
                    .collect(),
                any_significant: diagnosis
                    .ranking
                    .iter()
                    .any(|c| c.significant && !c.thermal_response),
                detectable_share: diagnosis.detectable_share,
                admitted: on_axis(a, true),
                refused: on_axis(a, false),
                before_dps: measured.iter().map(|r| r.drift_dps[a].0).collect(),
                after_dps: measured.iter().map(|r| r.drift_dps[a].1).collect(),
                floor_dps: floor.iter().map(|p| p[a].0).collect(),
            }
        })
        .collect())
}
