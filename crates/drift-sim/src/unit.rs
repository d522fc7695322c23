//! Per-unit physical parameters, drawn from a seeded generator.
//!
//! Every number is drawn uniformly from a range (see [`RANGES`] and `docs/simulator.md`),
//! so units differ the way parts from one production lot differ. The draws for the base
//! model, and for each hidden effect, come from separate streams.

use crate::hidden::HiddenEffects;
use crate::rng;
use crate::thermal::network::ThermalParams;
use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Reference temperature for the bias polynomial and the capsule pressure (°C).
pub const REFERENCE_CELSIUS: f64 = 25.0;
pub use drift_recording::RAW_PER_CELSIUS;
/// Nominal supply voltage (V).
pub const NOMINAL_SUPPLY_V: f64 = 5.0;

/// What kind of unit to simulate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnitModel {
    /// The full physical model.
    #[default]
    Physical,
    /// No systematic drift at all: same heating, same noise, zero temperature
    /// coefficients and no hidden effects. The noise floor for evaluations.
    ZeroSystematicDrift,
    /// A unit the paper's model represents exactly: the bias follows the temperature at the
    /// sensor's site, linearly (no element lagging the sensor, no curvature). Same heating and
    /// noise as [`UnitModel::Physical`]. Without hidden effects it is a true null case for the
    /// closed loop's diagnosis, which the physical unit is not: its element lags its sensor.
    PaperExact,
}

/// The bias and noise parameters of one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisParams {
    /// Constant bias offset (°/s).
    pub bias_offset_dps: f64,
    /// Linear temperature coefficient of bias at 25 °C, on the element temperature ((°/s)/°C).
    pub tempco_dps_per_c: f64,
    /// Quadratic coefficient ((°/s)/°C²): makes the slope depend on the ambient.
    pub tempco2_dps_per_c2: f64,
    /// Bias per relative change of capsule gas pressure ((°/s) per unit p/p_ref); the gas is at
    /// the capsule's temperature.
    pub pressure_dps: f64,
    /// Share of the temperature coefficients that follows the capsule rather than the element
    /// (packaging stress: the die is held by its capsule, which heats later).
    pub capsule_weight: f64,
    /// Turn-on to turn-on repeatability of the bias, 1σ (°/s).
    pub turn_on_sigma_dps: f64,
    /// White rate noise density (angle random walk), (°/s)/√Hz.
    pub white_noise_dps_per_rt_hz: f64,
    /// Bias instability as a first-order Gauss–Markov process: stationary 1σ (°/s).
    pub instability_sigma_dps: f64,
    /// Correlation time of the Gauss–Markov bias instability (s).
    pub instability_tau_s: f64,
    /// Temperature-sensor offset (°C): the sensor does not read the true ASIC temperature.
    pub temperature_offset_c: f64,
    /// Temperature-sensor white noise, 1σ in raw units (before quantisation).
    pub temperature_noise_raw: f64,
    /// (a) Hidden: bias per element heating rate ((°/s)/(°C/s)); 0 when off.
    pub thermal_lag_dps_per_c_per_s: f64,
    /// (b) Hidden: bias per acceleration along body X, Y, Z ((°/s)/g); 0 when off.
    pub accel_dps_per_g: [f64; 3],
    /// (c) Hidden: bias per volt of supply deviation ((°/s)/V); 0 when off.
    pub supply_dps_per_v: f64,
    /// (f) Hidden: bias creep ((°/s)/day); 0 when off.
    pub ageing_offset_dps_per_day: f64,
    /// (f) Hidden: relative change of the temperature coefficients per day; 0 when off.
    pub ageing_tempco_per_day: f64,
}

/// The accelerometer recorded as an auxiliary channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccelParams {
    /// Bias per axis (g).
    pub bias_g: [f64; 3],
    /// White noise per 100 Hz sample, 1σ (g).
    pub noise_g: f64,
}

/// Everything that makes one simulated unit itself.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitParams {
    /// Human-readable id, e.g. `GIU-01`.
    pub unit_id: String,
    /// Index of the unit in the campaign (0-based).
    pub index: u32,
    /// Which model the unit follows.
    pub model: UnitModel,
    /// The thermal network.
    pub thermal: ThermalParams,
    /// X, Y, Z gyro axes.
    pub axes: [AxisParams; 3],
    /// The accelerometer.
    pub accel: AccelParams,
    /// (e) Hidden: relative ASIC power growth per °C above 25 °C; 0 when off.
    pub asic_power_per_c: f64,
}

/// `(name, low, high, unit)` for every uniformly drawn base parameter; `±` ranges are
/// drawn as a magnitude in `[low, high]` with a random sign.
pub const RANGES: &[(&str, f64, f64, &str)] = &[
    ("housing_j_per_k", 55.0, 75.0, "J/K"),
    ("board_j_per_k", 8.0, 12.0, "J/K"),
    ("asic_j_per_k", 0.3, 0.5, "J/K"),
    ("element_j_per_k", 0.2, 0.3, "J/K"),
    ("housing_to_ambient_w_per_k", 0.26, 0.34, "W/K"),
    ("board_to_housing_w_per_k", 0.3, 0.4, "W/K"),
    ("asic_to_board_w_per_k", 0.016, 0.024, "W/K"),
    ("asic_to_element_w_per_k", 0.006, 0.010, "W/K"),
    ("element_to_housing_w_per_k", 0.002, 0.004, "W/K"),
    ("supply_power_w", 0.5, 0.7, "W"),
    ("asic_power_w", 0.05, 0.07, "W"),
    ("bias_offset_dps (uniform ±)", 0.0, 0.1, "°/s"),
    ("tempco_dps_per_c (±)", 0.004, 0.012, "(°/s)/°C"),
    ("tempco2_dps_per_c2 (±)", 0.5e-4, 1.5e-4, "(°/s)/°C²"),
    ("pressure_dps (±)", 0.1, 0.3, "°/s per p/p_ref"),
    ("turn_on_sigma_dps", 0.002, 0.005, "°/s"),
    ("white_noise_dps_per_rt_hz", 1.0e-4, 3.0e-4, "(°/s)/√Hz"),
    ("instability_sigma_dps", 1.0e-4, 3.0e-4, "°/s"),
    ("instability_tau_s", 100.0, 300.0, "s"),
    ("temperature_offset_c (uniform ±)", 0.0, 1.0, "°C"),
    ("temperature_noise_raw", 0.5, 1.5, "raw"),
    ("accel bias_g (uniform ±)", 0.0, 0.005, "g"),
    ("capsule_j_per_k", 0.3, 0.6, "J/K"),
    ("element_to_capsule_w_per_k", 0.002, 0.004, "W/K"),
    ("capsule_to_housing_w_per_k", 0.002, 0.004, "W/K"),
    ("capsule_weight", 0.1, 0.4, "–"),
];

fn range(rng: &mut ChaCha8Rng, name: &str) -> f64 {
    let (_, lo, hi, _) = RANGES
        .iter()
        .find(|r| r.0 == name)
        .copied()
        .unwrap_or((name, 0.0, 0.0, ""));
    lo + (hi - lo) * rng.random::<f64>()
}

fn signed(rng: &mut ChaCha8Rng, name: &str) -> f64 {
    let magnitude = range(rng, name);
    if rng.random::<bool>() {
        magnitude
    } else {
        -magnitude
    }
}

fn symmetric(rng: &mut ChaCha8Rng, name: &str) -> f64 {
    let (_, _, hi, _) = RANGES
        .iter()
        .find(|r| r.0 == name)
        .copied()
        .unwrap_or((name, 0.0, 0.0, ""));
    hi * (2.0 * rng.random::<f64>() - 1.0)
}

/// `magnitude × sign × U(0.5, 1.5)`: the per-axis draw of a hidden-effect coefficient.
fn effect_coefficient(rng: &mut ChaCha8Rng, magnitude: f64) -> f64 {
    let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
    magnitude * sign * (0.5 + rng.random::<f64>())
}

impl UnitParams {
    /// Draws unit `index` of a campaign with `seed`.
    pub fn draw(seed: u64, index: u32, model: UnitModel, effects: &HiddenEffects) -> Self {
        let mut r = rng::stream(seed, &[rng::tag("unit"), u64::from(index)]);
        let r = &mut r;
        let per_axis =
            |r: &mut ChaCha8Rng, name: &str| [range(r, name), range(r, name), range(r, name)];
        let thermal = ThermalParams {
            housing_j_per_k: range(r, "housing_j_per_k"),
            board_j_per_k: range(r, "board_j_per_k"),
            asic_j_per_k: per_axis(r, "asic_j_per_k"),
            element_j_per_k: per_axis(r, "element_j_per_k"),
            housing_to_ambient_w_per_k: range(r, "housing_to_ambient_w_per_k"),
            board_to_housing_w_per_k: range(r, "board_to_housing_w_per_k"),
            asic_to_board_w_per_k: per_axis(r, "asic_to_board_w_per_k"),
            asic_to_element_w_per_k: per_axis(r, "asic_to_element_w_per_k"),
            element_to_housing_w_per_k: per_axis(r, "element_to_housing_w_per_k"),
            // Drawn below from a stream of their own, so the capsule leaves every other draw
            // of a seed unchanged.
            capsule_j_per_k: [0.0; 3],
            element_to_capsule_w_per_k: [0.0; 3],
            capsule_to_housing_w_per_k: [0.0; 3],
            cross_axis_w_per_k: 0.0,
            supply_power_w: range(r, "supply_power_w"),
            asic_power_w: per_axis(r, "asic_power_w"),
            supply_power_per_relative_volt: 2.0,
        };
        let axis = |r: &mut ChaCha8Rng| AxisParams {
            bias_offset_dps: symmetric(r, "bias_offset_dps (uniform ±)"),
            tempco_dps_per_c: signed(r, "tempco_dps_per_c (±)"),
            tempco2_dps_per_c2: signed(r, "tempco2_dps_per_c2 (±)"),
            pressure_dps: signed(r, "pressure_dps (±)"),
            capsule_weight: 0.0,
            turn_on_sigma_dps: range(r, "turn_on_sigma_dps"),
            white_noise_dps_per_rt_hz: range(r, "white_noise_dps_per_rt_hz"),
            instability_sigma_dps: range(r, "instability_sigma_dps"),
            instability_tau_s: range(r, "instability_tau_s"),
            temperature_offset_c: symmetric(r, "temperature_offset_c (uniform ±)"),
            temperature_noise_raw: range(r, "temperature_noise_raw"),
            thermal_lag_dps_per_c_per_s: 0.0,
            accel_dps_per_g: [0.0; 3],
            supply_dps_per_v: 0.0,
            ageing_offset_dps_per_day: 0.0,
            ageing_tempco_per_day: 0.0,
        };
        let mut axes = [axis(r), axis(r), axis(r)];
        let mut thermal = thermal;
        let capsule = &mut rng::stream(seed, &[rng::tag("capsule"), u64::from(index)]);
        thermal.capsule_j_per_k = per_axis(capsule, "capsule_j_per_k");
        thermal.element_to_capsule_w_per_k = per_axis(capsule, "element_to_capsule_w_per_k");
        thermal.capsule_to_housing_w_per_k = per_axis(capsule, "capsule_to_housing_w_per_k");
        if model == UnitModel::Physical {
            for a in &mut axes {
                a.capsule_weight = range(capsule, "capsule_weight");
            }
        }
        let accel = AccelParams {
            bias_g: [
                symmetric(r, "accel bias_g (uniform ±)"),
                symmetric(r, "accel bias_g (uniform ±)"),
                symmetric(r, "accel bias_g (uniform ±)"),
            ],
            noise_g: 0.001,
        };
        let mut unit = Self {
            unit_id: format!("GIU-{:02}", index + 1),
            index,
            model,
            thermal,
            axes: axes.clone(),
            accel,
            asic_power_per_c: 0.0,
        };
        if model == UnitModel::ZeroSystematicDrift {
            for a in &mut axes {
                a.tempco_dps_per_c = 0.0;
                a.tempco2_dps_per_c2 = 0.0;
                a.pressure_dps = 0.0;
            }
            unit.axes = axes;
            return unit;
        }
        if model == UnitModel::PaperExact {
            for a in &mut axes {
                a.tempco2_dps_per_c2 = 0.0;
            }
        }
        unit.axes = axes;
        unit.apply_effects(seed, effects);
        unit
    }

    /// Draws the hidden-effect coefficients, each from its own stream.
    fn apply_effects(&mut self, seed: u64, effects: &HiddenEffects) {
        let index = u64::from(self.index);
        let effect_rng =
            |name: &str| rng::stream(seed, &[rng::tag("effect"), rng::tag(name), index]);
        if let Some(e) = &effects.thermal_lag {
            let mut r = effect_rng("thermal_lag");
            for a in &mut self.axes {
                a.thermal_lag_dps_per_c_per_s = effect_coefficient(&mut r, e.dps_per_c_per_s);
            }
        }
        if let Some(e) = &effects.acceleration {
            let mut r = effect_rng("acceleration");
            for a in &mut self.axes {
                for g in &mut a.accel_dps_per_g {
                    let z: f64 = StandardNormal.sample(&mut r);
                    *g = e.dps_per_g * z;
                }
            }
        }
        if let Some(e) = &effects.supply_voltage {
            let mut r = effect_rng("supply_voltage");
            for a in &mut self.axes {
                a.supply_dps_per_v = effect_coefficient(&mut r, e.dps_per_v);
            }
        }
        if let Some(e) = &effects.cross_axis {
            self.thermal.cross_axis_w_per_k = e.w_per_k;
        }
        if let Some(e) = &effects.rise_nonlinearity {
            self.asic_power_per_c = e.per_c;
        }
        if let Some(e) = &effects.ageing {
            let mut r = effect_rng("ageing");
            for a in &mut self.axes {
                a.ageing_offset_dps_per_day = effect_coefficient(&mut r, e.offset_dps_per_day);
                a.ageing_tempco_per_day = effect_coefficient(&mut r, e.tempco_relative_per_day);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_are_reproducible_and_units_differ() {
        let none = HiddenEffects::default();
        let a = UnitParams::draw(42, 0, UnitModel::Physical, &none);
        let b = UnitParams::draw(42, 0, UnitModel::Physical, &none);
        let c = UnitParams::draw(42, 1, UnitModel::Physical, &none);
        assert_eq!(a, b);
        assert_ne!(a.thermal, c.thermal);
        assert_ne!(a.axes, c.axes);
    }

    #[test]
    fn switching_an_effect_on_keeps_base_parameters() {
        let none = HiddenEffects::default();
        let mut lag = HiddenEffects::default();
        lag.enable("thermal_lag").unwrap();
        let a = UnitParams::draw(5, 0, UnitModel::Physical, &none);
        let b = UnitParams::draw(5, 0, UnitModel::Physical, &lag);
        assert_eq!(a.thermal, b.thermal);
        for (x, y) in a.axes.iter().zip(&b.axes) {
            assert_eq!(x.tempco_dps_per_c, y.tempco_dps_per_c);
            assert_eq!(x.white_noise_dps_per_rt_hz, y.white_noise_dps_per_rt_hz);
            assert_eq!(x.thermal_lag_dps_per_c_per_s, 0.0);
            assert!(y.thermal_lag_dps_per_c_per_s.abs() >= 0.05);
        }
    }

    #[test]
    fn every_drawn_parameter_is_inside_its_documented_range() {
        let inside = |name: &str, values: &[f64]| {
            let (_, lo, hi, _) = RANGES.iter().find(|r| r.0 == name).copied().unwrap();
            for v in values {
                let m = if name.contains('±') { v.abs() } else { *v };
                let lo = if name.contains("uniform ±") { 0.0 } else { lo };
                assert!(m >= lo && m <= hi, "{name}: {v} outside [{lo}, {hi}]");
                assert!(*v != 0.0, "{name}: drawn as exactly 0 (unknown name?)");
            }
        };
        for index in 0..20 {
            let u = UnitParams::draw(99, index, UnitModel::Physical, &HiddenEffects::default());
            let t = &u.thermal;
            inside("housing_j_per_k", &[t.housing_j_per_k]);
            inside("board_j_per_k", &[t.board_j_per_k]);
            inside("asic_j_per_k", &t.asic_j_per_k);
            inside("element_j_per_k", &t.element_j_per_k);
            inside(
                "housing_to_ambient_w_per_k",
                &[t.housing_to_ambient_w_per_k],
            );
            inside("board_to_housing_w_per_k", &[t.board_to_housing_w_per_k]);
            inside("asic_to_board_w_per_k", &t.asic_to_board_w_per_k);
            inside("asic_to_element_w_per_k", &t.asic_to_element_w_per_k);
            inside("element_to_housing_w_per_k", &t.element_to_housing_w_per_k);
            inside("capsule_j_per_k", &t.capsule_j_per_k);
            inside("element_to_capsule_w_per_k", &t.element_to_capsule_w_per_k);
            inside("capsule_to_housing_w_per_k", &t.capsule_to_housing_w_per_k);
            inside("supply_power_w", &[t.supply_power_w]);
            inside("asic_power_w", &t.asic_power_w);
            inside("accel bias_g (uniform ±)", &u.accel.bias_g);
            for a in &u.axes {
                inside("bias_offset_dps (uniform ±)", &[a.bias_offset_dps]);
                inside("tempco_dps_per_c (±)", &[a.tempco_dps_per_c]);
                inside("tempco2_dps_per_c2 (±)", &[a.tempco2_dps_per_c2]);
                inside("pressure_dps (±)", &[a.pressure_dps]);
                inside("capsule_weight", &[a.capsule_weight]);
                inside("turn_on_sigma_dps", &[a.turn_on_sigma_dps]);
                inside("white_noise_dps_per_rt_hz", &[a.white_noise_dps_per_rt_hz]);
                inside("instability_sigma_dps", &[a.instability_sigma_dps]);
                inside("instability_tau_s", &[a.instability_tau_s]);
                inside(
                    "temperature_offset_c (uniform ±)",
                    &[a.temperature_offset_c],
                );
                inside("temperature_noise_raw", &[a.temperature_noise_raw]);
            }
        }
    }

    #[test]
    fn zero_drift_unit_has_no_temperature_coefficients() {
        let u = UnitParams::draw(
            1,
            0,
            UnitModel::ZeroSystematicDrift,
            &HiddenEffects::default(),
        );
        for a in &u.axes {
            assert_eq!(
                (a.tempco_dps_per_c, a.tempco2_dps_per_c2, a.pressure_dps),
                (0.0, 0.0, 0.0)
            );
            assert!(a.white_noise_dps_per_rt_hz > 0.0);
        }
    }
}
