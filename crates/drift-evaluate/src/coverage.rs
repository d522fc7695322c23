//! Where the tables are valid: a coverage map of the calibration's switch-on temperatures ×
//! residual heats, with the number of calibration activations behind each cell, and how much of
//! the held-out data fell outside the envelope.
//!
//! The envelope is drift-core's [`Envelope`], per axis, as the recommended model's corrector
//! flags it at switch-on (`TEMPERATURE_OUT_OF_RANGE`, `HISTORY_OUT_OF_SPAN`): the map places the
//! activations, the envelope says which are outside. A cell inside the envelope with no
//! calibration activation behind it is inside by the corrector's flags but was never measured; the
//! map shows it, and the held-out share in such cells is counted apart.

pub use drift_core::Envelope;
use drift_core::SwitchOn;
use drift_fit::analyse::Analysed;
use drift_fit::curves::CurveKey;
use drift_fit::settings::FitSettings;
use drift_fit::turn_on::residual_heats;
use drift_fit::FittedUnit;
use serde::Serialize;

use crate::summary::Split;
use crate::uncertainty::Residuals;

/// Width of a map cell in switch-on temperature, °C.
pub const SWITCH_ON_CELL_CELSIUS: f64 = 2.0;

/// Height of a map cell in residual heat, °C.
pub const RESIDUAL_HEAT_CELL_CELSIUS: f64 = 1.0;

/// One cell of the map: its corner and how many activations fell in it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// The cell's lowest switch-on temperature, °C (it spans [`SWITCH_ON_CELL_CELSIUS`]).
    pub switch_on_celsius: f64,
    /// The cell's lowest residual heat, °C (it spans [`RESIDUAL_HEAT_CELL_CELSIUS`]).
    pub residual_heat_celsius: f64,
    /// Calibration activations in the cell (the tables were fitted on them).
    pub calibration_activations: usize,
    /// Held-out activations (validation and field) in the cell.
    pub held_out_activations: usize,
}

/// How much of one held-out split fell outside the envelope.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Outside {
    /// The split's name ([`Split::name`]).
    pub split: &'static str,
    /// Activation × axis pairs.
    pub axis_activations: usize,
    /// Of them, outside their axis's envelope.
    pub axis_activations_outside: usize,
    /// Residual samples (every [`crate::uncertainty::EVERY_MS`], every axis).
    pub samples: usize,
    /// Of them, in an activation outside its axis's envelope.
    pub samples_outside: usize,
    /// Activations (not axes) inside every axis's envelope but in a cell without calibration
    /// activations: inside by the flags, never measured.
    pub activations_in_empty_cells: usize,
    /// Activations (not axes).
    pub activations: usize,
}

impl Outside {
    /// The share of activation × axis pairs outside (NaN for none).
    pub fn axis_activation_share(&self) -> f64 {
        self.axis_activations_outside as f64 / self.axis_activations as f64
    }

    /// The share of samples outside (NaN for none).
    pub fn sample_share(&self) -> f64 {
        self.samples_outside as f64 / self.samples as f64
    }
}

/// One unit's coverage map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitCoverage {
    /// The unit.
    pub unit_id: String,
    /// The envelope per axis (X, Y, Z), as the recommended model's corrector flags it.
    pub envelope: [Envelope; 3],
    /// Calibration activations placed on the map.
    pub calibration_activations: usize,
    /// Every cell with an activation, calibration or held out, by switch-on temperature then
    /// residual heat. An activation sits at its axes' mean switch-on temperature and residual heat.
    pub cells: Vec<Cell>,
    /// Per held-out split (validation, field), the share outside the envelope.
    pub outside: Vec<Outside>,
}

fn cell_key(switch_on_celsius: f64, residual_heat_celsius: f64) -> Option<(i64, i64)> {
    let t = (switch_on_celsius / SWITCH_ON_CELL_CELSIUS).floor();
    let h = (residual_heat_celsius.max(0.0) / RESIDUAL_HEAT_CELL_CELSIUS).floor();
    (t.is_finite() && h.is_finite()).then_some((t as i64, h as i64))
}

fn mean3(values: [f64; 3]) -> f64 {
    values.iter().sum::<f64>() / 3.0
}

fn held_out_key(switch_on: &[SwitchOn; 3]) -> Option<(i64, i64)> {
    cell_key(
        mean3(switch_on.map(|s| f64::from(s.switch_on_celsius))),
        mean3(switch_on.map(|s| {
            if s.known {
                f64::from(s.residual_heat_celsius)
            } else {
                0.0
            }
        })),
    )
}

/// The map of one unit: `envelope` per axis, `calibration` the (switch-on temperature, residual
/// heat) of each activation the tables were fitted on (°C, means over axes), `held_out` its
/// validation and field residuals (their switch-ons as firmware estimated them).
pub fn map(
    unit_id: &str,
    envelope: [Envelope; 3],
    calibration: &[(f64, f64)],
    held_out: &[(Split, &Residuals)],
) -> UnitCoverage {
    let mut cells: std::collections::BTreeMap<(i64, i64), (usize, usize)> = Default::default();
    for &(switch_on, heat) in calibration {
        if let Some(key) = cell_key(switch_on, heat) {
            cells.entry(key).or_default().0 += 1;
        }
    }
    let mut outside: Vec<Outside> = Vec::new();
    for split in [Split::Validation, Split::Field] {
        let mut o = Outside {
            split: split.name(),
            axis_activations: 0,
            axis_activations_outside: 0,
            samples: 0,
            samples_outside: 0,
            activations_in_empty_cells: 0,
            activations: 0,
        };
        for (_, r) in held_out.iter().filter(|(s, _)| *s == split) {
            o.activations += 1;
            let key = held_out_key(&r.switch_on);
            let calibrated = key
                .and_then(|k| cells.get(&k))
                .is_some_and(|(calibration, _)| *calibration > 0);
            if let Some(key) = key {
                cells.entry(key).or_default().1 += 1;
            }
            let mut every_axis_inside = true;
            for (e, s) in envelope.iter().zip(&r.switch_on) {
                o.axis_activations += 1;
                o.samples += r.samples.len();
                if !e.contains(s) {
                    every_axis_inside = false;
                    o.axis_activations_outside += 1;
                    o.samples_outside += r.samples.len();
                }
            }
            if every_axis_inside && !calibrated {
                o.activations_in_empty_cells += 1;
            }
        }
        if o.activations > 0 {
            outside.push(o);
        }
    }
    UnitCoverage {
        unit_id: unit_id.to_owned(),
        envelope,
        calibration_activations: calibration.len(),
        cells: cells
            .into_iter()
            .map(|((t, h), (calibration, held_out))| Cell {
                switch_on_celsius: t as f64 * SWITCH_ON_CELL_CELSIUS,
                residual_heat_celsius: h as f64 * RESIDUAL_HEAT_CELL_CELSIUS,
                calibration_activations: calibration,
                held_out_activations: held_out,
            })
            .collect(),
        outside,
    }
}

/// The map of every unit of `fitted`: its calibration activations the turn-on bias was fitted on
/// (those with a protocol curve key under `settings`, as the fit chooses them).
pub fn per_unit(
    fitted: &[FittedUnit],
    calibration: &[Analysed],
    residuals: &[(Split, Residuals)],
    settings: &FitSettings,
) -> Vec<UnitCoverage> {
    fitted
        .iter()
        .map(|unit| {
            let mine: Vec<&Analysed> = calibration
                .iter()
                .filter(|a| a.labels.unit_id == unit.unit_id && CurveKey::of(a, settings).is_some())
                .collect();
            let held_out: Vec<(Split, &Residuals)> = residuals
                .iter()
                .filter(|(s, r)| {
                    matches!(s, Split::Validation | Split::Field) && r.unit_id == unit.unit_id
                })
                .map(|(s, r)| (*s, r))
                .collect();
            let margin = unit.recommended.settings.ambient_margin_celsius;
            let envelope =
                std::array::from_fn(|a| unit.recommended.axes[a].turn_on.envelope(margin));
            // The residual heats as the turn-on fit estimated them, series by series.
            let heats: [Vec<f64>; 3] = std::array::from_fn(|a| residual_heats(&mine, a));
            let points: Vec<(f64, f64)> = mine
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    (
                        mean3(a.switch_on_celsius),
                        mean3(std::array::from_fn(|axis| heats[axis][i])),
                    )
                })
                .collect();
            map(&unit.unit_id, envelope, &points, &held_out)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn held_out(on: f32, heat: f32, samples: usize) -> Residuals {
        let s = SwitchOn {
            switch_on_celsius: on,
            ambient_celsius: on - heat,
            residual_heat_celsius: heat,
            remaining: 0.0,
            known: true,
        };
        Residuals {
            unit_id: "U".into(),
            set_point_celsius: 33.0,
            switch_on: [s; 3],
            mean_uncorrected_dps: [0.0; 3],
            samples: vec![(0, [0.0; 3]); samples],
        }
    }

    #[test]
    fn cells_count_activations_and_the_envelope_says_what_is_outside() {
        let envelope = Envelope {
            switch_on_celsius: [30.0, 44.0],
            margin_celsius: 0.5,
            most_residual_heat_celsius: 5.0,
        };
        let calibration = [(30.2, 0.0), (31.9, 0.3), (40.0, 4.5), (40.5, 4.9)];
        let inside = held_out(33.0, 0.0, 10);
        let empty_cell = held_out(36.0, 3.0, 10);
        let too_warm = held_out(40.0, 6.0, 20);
        let cold_field = held_out(25.0, 0.0, 5);
        let m = map(
            "U",
            [envelope; 3],
            &calibration,
            &[
                (Split::Validation, &inside),
                (Split::Field, &empty_cell),
                (Split::Field, &too_warm),
                (Split::Field, &cold_field),
            ],
        );
        let at = |t: f64, h: f64| {
            m.cells
                .iter()
                .find(|c| c.switch_on_celsius == t && c.residual_heat_celsius == h)
                .map(|c| (c.calibration_activations, c.held_out_activations))
        };
        assert_eq!(at(30.0, 0.0), Some((2, 0)));
        assert_eq!(at(40.0, 4.0), Some((2, 0)));
        assert_eq!(at(32.0, 0.0), Some((0, 1)));
        assert_eq!(at(40.0, 6.0), Some((0, 1)));
        assert_eq!(m.outside.len(), 2);
        let validation = m.outside[0];
        assert_eq!(
            (
                validation.split,
                validation.axis_activations_outside,
                validation.activations_in_empty_cells
            ),
            ("validation", 0, 1),
            "inside the envelope, in a cell the calibration never had"
        );
        let field = m.outside[1];
        assert_eq!((field.activations, field.axis_activations), (3, 9));
        assert_eq!(field.axis_activations_outside, 6);
        assert_eq!((field.samples, field.samples_outside), (105, 75));
        assert!((field.sample_share() - 75.0 / 105.0).abs() < 1e-12);
        assert_eq!(field.activations_in_empty_cells, 1);
    }
}
