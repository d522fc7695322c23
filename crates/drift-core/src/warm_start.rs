//! The initial bias of a warm start: how far the switch-on bias of a unit that was off only
//! briefly stands from a cold start's at the same ambient.
//!
//! The paper reads the initial bias from the switch-on temperature alone, as its fully cooled
//! calibration starts saw it. After a short off-time the unit is not in equilibrium when it switches
//! on: the sensing element, which the temperature sensor only follows, is at another temperature
//! than the sensor and still cooling, and a bias with any dependence on the element's temperature
//! or its rate then starts elsewhere. The calibration's own series of activations measure the
//! initial bias at each off-time; firmware finds it by the ambient and the residual heat at
//! switch-on ([`crate::SwitchOn`]), from what it kept of the previous activation.

use crate::error::{check_finite, check_increasing, Error, Location, Problem};
use crate::interp::{bracket, lerp, Bracket};

/// One warm start of the calibration: the residual heat it switched on with and its initial bias
/// less a cold start's at its switch-on temperature.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct WarmStart {
    /// How far the switch-on temperature stood above the ambient, °C (> 0).
    pub residual_heat_celsius: f32,
    /// Initial bias less the cold start's at the same ambient (the table's `initial_bias_dps`),
    /// °/s.
    pub bias_offset_dps: f32,
}

/// The initial-bias offset at `residual_heat_celsius` from the warm starts of one ambient (in
/// increasing residual heat): zero for a cold start, linear between the calibrated warm starts
/// (from a cold start's zero up to the first), and held at the warmest beyond it (where the table
/// flags the start `HISTORY_OUT_OF_SPAN`).
#[inline]
pub(crate) fn offset_dps(warm_starts: &[WarmStart], residual_heat_celsius: f32) -> f32 {
    // NaN included: no usable residual heat is a cold start.
    if residual_heat_celsius.is_nan() || residual_heat_celsius <= 0.0 {
        return 0.0;
    }
    let heat = |w: &WarmStart| w.residual_heat_celsius;
    match bracket(warm_starts, residual_heat_celsius, heat) {
        Bracket::Below => {
            let first = warm_starts.first().copied().unwrap_or_default();
            if first.residual_heat_celsius > 0.0 {
                first.bias_offset_dps * (residual_heat_celsius / first.residual_heat_celsius)
            } else {
                0.0
            }
        }
        Bracket::Inside { lo, fraction } => {
            let at = |i: usize| warm_starts.get(i).map_or(f32::NAN, |w| w.bias_offset_dps);
            if fraction > 0.0 {
                lerp(at(lo), at(lo.saturating_add(1)), fraction)
            } else {
                at(lo)
            }
        }
        Bracket::Above => warm_starts.last().map_or(0.0, |w| w.bias_offset_dps),
    }
}

/// Checks one ambient's warm starts: residual heats positive and strictly increasing, offsets
/// finite. `at` names the axis and ambient.
pub(crate) fn validate(warm_starts: &[WarmStart], at: Location) -> Result<(), Error> {
    let field = "warm_starts";
    if let Some(first) = warm_starts.first() {
        if first.residual_heat_celsius <= 0.0 {
            return Err(Error::new(field, at.index(0), Problem::NotPositive));
        }
    }
    check_increasing(
        field,
        at,
        warm_starts.iter().map(|w| w.residual_heat_celsius),
    )?;
    check_finite(field, at, warm_starts.iter().map(|w| w.bias_offset_dps))
}

#[cfg(test)]
mod tests {
    use super::*;

    const WARM: [WarmStart; 2] = [
        WarmStart {
            residual_heat_celsius: 1.0,
            bias_offset_dps: -0.004,
        },
        WarmStart {
            residual_heat_celsius: 3.0,
            bias_offset_dps: -0.010,
        },
    ];

    #[test]
    fn a_cold_start_has_no_offset() {
        assert_eq!(offset_dps(&WARM, 0.0), 0.0);
        assert_eq!(offset_dps(&WARM, -0.5), 0.0);
        assert_eq!(offset_dps(&WARM, f32::NAN), 0.0);
        assert_eq!(offset_dps(&[], 2.0), 0.0);
    }

    #[test]
    fn interpolates_from_cold_through_the_warm_starts_and_holds_beyond() {
        assert!((offset_dps(&WARM, 0.5) - -0.002).abs() < 1e-9);
        assert_eq!(offset_dps(&WARM, 1.0), -0.004);
        assert!((offset_dps(&WARM, 2.0) - -0.007).abs() < 1e-9);
        assert_eq!(offset_dps(&WARM, 3.0), -0.010);
        assert_eq!(offset_dps(&WARM, 9.0), -0.010);
    }

    #[test]
    fn validation_names_the_warm_start() {
        assert!(validate(&WARM, Location::axis(1)).is_ok());
        let mut bad = WARM;
        bad[1].residual_heat_celsius = 1.0;
        let e = validate(&bad, Location::axis(1)).unwrap_err();
        assert_eq!((e.field, e.at.index), ("warm_starts", Some(1)));
        let mut bad = WARM;
        bad[0].residual_heat_celsius = 0.0;
        let e = validate(&bad, Location::axis(1)).unwrap_err();
        assert_eq!(e.at.index, Some(0));
        let mut bad = WARM;
        bad[1].bias_offset_dps = f32::INFINITY;
        let e = validate(&bad, Location::axis(1)).unwrap_err();
        assert_eq!(e.at.index, Some(1));
    }
}
