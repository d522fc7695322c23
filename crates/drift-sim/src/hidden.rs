//! Effects that can be hidden in the truth without the fitter being told.
//!
//! Each effect is off by default (`None`); writing its table in the campaign file (e.g.
//! `[effects.thermal_lag]`) switches it on with default magnitudes, which can be
//! overridden. Effects compose: any subset may be on at once. Per-axis coefficients are
//! drawn per unit as `magnitude × sign × U(0.5, 1.5)` from a stream of their own, so
//! switching an effect on never changes the unit's base parameters.
//!
//! The auxiliary channels (accelerometer, supply voltage, chamber set point) are recorded
//! whatever is switched on, so their presence reveals nothing.

use serde::{Deserialize, Serialize};

/// The switchable effects of a campaign (all off by default).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HiddenEffects {
    /// (a) Bias proportional to the element's heating rate `dT_e/dt` (thermal gradient
    /// across the die), beyond the lag already in the base network.
    pub thermal_lag: Option<ThermalLag>,
    /// (b) Bias proportional to linear acceleration (gravity in the body frame, so it
    /// changes when the orientation changes between activations).
    pub acceleration: Option<AccelerationSensitivity>,
    /// (c) Bias proportional to the supply voltage's deviation from nominal.
    pub supply_voltage: Option<SupplyVoltageSensitivity>,
    /// (d) Cross-axis thermal coupling: each element is also heated by the other two
    /// sensors' ASICs (extra conductances in the network).
    pub cross_axis: Option<CrossAxisCoupling>,
    /// (e) Nonlinear temperature rise: ASIC dissipation grows with its own temperature
    /// (CMOS leakage), so the rise is no longer proportional to the power.
    pub rise_nonlinearity: Option<RiseNonlinearity>,
    /// (f) Slow ageing: the bias offset creeps and the temperature coefficient changes
    /// over campaign time.
    pub ageing: Option<Ageing>,
}

/// (a) Temperature-rate term.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ThermalLag {
    /// Typical |coefficient| in (°/s) per (°C/s) of element heating rate.
    pub dps_per_c_per_s: f64,
}
impl Default for ThermalLag {
    fn default() -> Self {
        // The element heats at up to ~0.05 °C/s just after switch-on: 0.1 gives ~0.005 °/s,
        // a fraction of the base drift, like the rate terms reported for MEMS gyros.
        Self {
            dps_per_c_per_s: 0.1,
        }
    }
}

/// (b) g-sensitivity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AccelerationSensitivity {
    /// Standard deviation of each entry of the 3×3 sensitivity matrix, (°/s)/g.
    pub dps_per_g: f64,
}
impl Default for AccelerationSensitivity {
    fn default() -> Self {
        // Navigation-grade MEMS gyros quote 0.001–0.01 °/s/g; consumer parts 0.1.
        Self { dps_per_g: 0.005 }
    }
}

/// (c) Supply-voltage sensitivity of the bias.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SupplyVoltageSensitivity {
    /// Typical |coefficient| in (°/s)/V.
    pub dps_per_v: f64,
}
impl Default for SupplyVoltageSensitivity {
    fn default() -> Self {
        // Data sheets quote bias vs supply of 0.01–0.1 °/s/V for ratiometric MEMS parts.
        Self { dps_per_v: 0.01 }
    }
}

/// (d) Cross-axis thermal coupling.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CrossAxisCoupling {
    /// Conductance from each element to each other axis's ASIC (W/K).
    pub w_per_k: f64,
}
impl Default for CrossAxisCoupling {
    fn default() -> Self {
        // A quarter of the own ASIC → element path (~0.008 W/K): sensors a few mm apart.
        Self { w_per_k: 0.002 }
    }
}

/// (e) Temperature-dependent ASIC dissipation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RiseNonlinearity {
    /// Relative growth of ASIC power per °C above 25 °C (1/°C).
    pub per_c: f64,
}
impl Default for RiseNonlinearity {
    fn default() -> Self {
        // Leakage doubles every ~10 °C but is a minority of the ASIC's power: ~2 %/°C overall.
        Self { per_c: 0.02 }
    }
}

/// (f) Ageing over campaign time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ageing {
    /// Typical |bias offset creep| in (°/s) per day of campaign time.
    pub offset_dps_per_day: f64,
    /// Typical |relative change of the temperature coefficient| per day.
    pub tempco_relative_per_day: f64,
}
impl Default for Ageing {
    fn default() -> Self {
        // A default campaign lasts ~4 days; this moves the offset by ~0.02 °/s and the
        // temperature coefficient by ~4 % over it: visible to a careful fitter, not loud.
        Self {
            offset_dps_per_day: 0.005,
            tempco_relative_per_day: 0.01,
        }
    }
}

impl HiddenEffects {
    /// Names of the effects that are on, for labels and logs.
    pub fn active(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        for (on, name) in [
            (self.thermal_lag.is_some(), "thermal_lag"),
            (self.acceleration.is_some(), "acceleration"),
            (self.supply_voltage.is_some(), "supply_voltage"),
            (self.cross_axis.is_some(), "cross_axis"),
            (self.rise_nonlinearity.is_some(), "rise_nonlinearity"),
            (self.ageing.is_some(), "ageing"),
        ] {
            if on {
                names.push(name);
            }
        }
        names
    }

    /// Switches an effect on by name with default magnitudes.
    pub fn enable(&mut self, name: &str) -> Result<(), String> {
        match name {
            "thermal_lag" => self.thermal_lag = Some(ThermalLag::default()),
            "acceleration" => self.acceleration = Some(AccelerationSensitivity::default()),
            "supply_voltage" => self.supply_voltage = Some(SupplyVoltageSensitivity::default()),
            "cross_axis" => self.cross_axis = Some(CrossAxisCoupling::default()),
            "rise_nonlinearity" => self.rise_nonlinearity = Some(RiseNonlinearity::default()),
            "ageing" => self.ageing = Some(Ageing::default()),
            other => {
                return Err(format!(
                    "unknown effect `{other}`; known: thermal_lag, acceleration, supply_voltage, cross_axis, rise_nonlinearity, ageing"
                ))
            }
        }
        Ok(())
    }
}
