//! The gyro bias model: what the rate output reads when the unit is not rotating.
//!
//! ```text
//! b(t) = b₀ + j_k                                     offset + turn-on jitter of activation k
//!      + s_age(t) · [ c₁ ΔT_s + c₂ ΔT_s² + c_p (p/p_ref − 1) ]  systematic thermal drift
//!      + (hidden effects)                              rate term, g-sensitivity, supply, ageing creep
//!      + β(t) + w(t)                                    bias instability (Gauss–Markov) + white noise
//! ΔT_s = (1 − w) T_e + w T_c − 25 °C                   the structure's temperature: element and capsule
//! p/p_ref = (T_c + 273.15) / (25 + 273.15)             sealed capsule: isochoric gas at the capsule's T
//! ```
//!
//! `T_e` is the element temperature, not the sensor's: the sensor sits on the ASIC and the
//! element lags it, which is what makes the drift/rise ratio depend on heating history. The
//! capsule `T_c` lags the element again, so the bias is not a function of any one temperature
//! the unit can measure: no table of the sensor's temperature represents it exactly.

use crate::unit::{AxisParams, NOMINAL_SUPPLY_V, REFERENCE_CELSIUS};

/// Seconds per day, for ageing rates.
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// Inputs the systematic bias depends on at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasInputs {
    /// Element temperature (°C).
    pub element_c: f64,
    /// Capsule (glass and gas) temperature (°C).
    pub capsule_c: f64,
    /// Element heating rate (°C/s); used only by the hidden thermal-lag term.
    pub element_rate_c_per_s: f64,
    /// True specific force in the body frame (g); used only by the hidden g-sensitivity.
    pub accel_g: [f64; 3],
    /// Supply voltage (V); used only by the hidden supply term.
    pub supply_v: f64,
    /// Campaign time (s); used only by hidden ageing.
    pub campaign_s: f64,
}

/// Capsule gas pressure relative to its value at 25 °C, for gas at `gas_c`.
pub fn relative_pressure(gas_c: f64) -> f64 {
    // Multiplying by the constant's inverse keeps a division out of the per-sample loop.
    const INV_REFERENCE_KELVIN: f64 = 1.0 / (REFERENCE_CELSIUS + 273.15);
    (gas_c + 273.15) * INV_REFERENCE_KELVIN
}

/// The noise-free bias of one axis (°/s), without the turn-on jitter.
#[inline]
pub fn systematic_dps(axis: &AxisParams, x: &BiasInputs) -> f64 {
    const DAYS_PER_SECOND: f64 = 1.0 / SECONDS_PER_DAY;
    let days = x.campaign_s * DAYS_PER_SECOND;
    let structure_c = x.element_c + axis.capsule_weight * (x.capsule_c - x.element_c);
    let dt = structure_c - REFERENCE_CELSIUS;
    let thermal = axis.tempco_dps_per_c * dt
        + axis.tempco2_dps_per_c2 * dt * dt
        + axis.pressure_dps * (relative_pressure(x.capsule_c) - 1.0);
    let ageing_scale = 1.0 + axis.ageing_tempco_per_day * days;
    let accel: f64 = axis
        .accel_dps_per_g
        .iter()
        .zip(&x.accel_g)
        .map(|(k, a)| k * a)
        .sum();
    axis.bias_offset_dps
        + ageing_scale * thermal
        + axis.ageing_offset_dps_per_day * days
        + axis.thermal_lag_dps_per_c_per_s * x.element_rate_c_per_s
        + accel
        + axis.supply_dps_per_v * (x.supply_v - NOMINAL_SUPPLY_V)
}
