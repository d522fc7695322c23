//! How much bias the correction leaves, and when: the residual bias's standard deviation σ(t) as a
//! function of time since switch-on, activation class (cold start, warm restart) and distance of
//! the switch-on ambient from the calibrated envelope. An attitude or navigation filter takes it as
//! the gyro bias's uncertainty (process or measurement noise of its bias state).
//!
//! It is a call of its own beside [`crate::Corrector::correct`], not part of it: the tables and the
//! corrector's per-sample work are unchanged, and firmware without a filter that reads σ leaves it
//! out. Fitted by drift-evaluate from residuals on calibration activations the tables did not see.
//!
//! ```
//! use drift_core::{Previous, SwitchOn, Uncertainty};
//!
//! let sigma = Uncertainty {
//!     knots_ms: [0, 2_000, 5_000, 10_000, 20_000, 40_000, 80_000, 160_000],
//!     sigma_dps: [[0.004, 0.003, 0.002, 0.002, 0.001, 0.001, 0.001, 0.001],
//!                 [0.008, 0.006, 0.004, 0.003, 0.002, 0.002, 0.001, 0.001]],
//!     warm_above_celsius: 0.5,
//!     ambient_min_celsius: 30.0,
//!     ambient_max_celsius: 40.0,
//!     per_celsius_outside_dps: 0.0005,
//!     most_residual_heat_celsius: [6.0; 3],
//!     per_residual_celsius_beyond_dps: 0.001,
//! };
//! sigma.validate()?;
//! // At switch-on, before `power_on_after` overwrites what was kept: 34 °C after an activation
//! // that left the unit at 36 °C in a 30 °C ambient (4 °C of residual heat: a warm restart).
//! let kept = Previous { ambient_celsius: 30.0, switch_off_celsius: 36.0 };
//! let state = sigma.start(&[SwitchOn::estimate(34.0, Some(kept)); 3]);
//! // Beside each corrected sample: the filter's gyro-bias σ per axis, °/s.
//! assert_eq!(sigma.sigma_dps(&state, 1_000), [0.007; 3]);
//! # Ok::<(), drift_core::Error>(())
//! ```

use crate::envelope::heat_beyond;
use crate::error::{Error, Location, Problem};
use crate::history::SwitchOn;
use crate::AXES;

/// Knots of σ(t) per class: times since switch-on, piecewise linear between them, held after the
/// last.
pub const SIGMA_KNOTS: usize = 8;

/// The activation classes σ(t) is fitted for ([`ActivationClass`]).
pub const ACTIVATION_CLASSES: usize = 2;

/// How an activation started, as firmware tells it from what it kept of the previous one
/// ([`SwitchOn`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(u8)]
pub enum ActivationClass {
    /// No residual heat above [`Uncertainty::warm_above_celsius`] (or nothing kept).
    #[default]
    Cold = 0,
    /// Switched on with residual heat of the previous activation still in the unit.
    WarmRestart = 1,
}

impl ActivationClass {
    /// Every class, in the order of [`Uncertainty::sigma_dps`]'s rows.
    pub const ALL: [Self; ACTIVATION_CLASSES] = [Self::Cold, Self::WarmRestart];

    /// The name used in reports: `cold start`, `warm restart`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cold => "cold start",
            Self::WarmRestart => "warm restart",
        }
    }
}

/// The fitted σ(t) of one unit (every axis): 8 knots × 2 classes plus the envelope, 108 bytes.
///
/// σ(t) = the class's piecewise-linear curve through (`knots_ms`, `sigma_dps[class]`) at the time
/// since switch-on (held after the last knot) + `per_celsius_outside_dps` × how far the switch-on
/// ambient lies outside `ambient_min_celsius ..= ambient_max_celsius`, °C +
/// `per_residual_celsius_beyond_dps` × how far the residual heat at switch-on lies beyond the
/// axis's `most_residual_heat_celsius`, °C.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Uncertainty {
    /// Knot times since switch-on, ms: the first 0, strictly increasing.
    pub knots_ms: [u32; SIGMA_KNOTS],
    /// σ at each knot, °/s, per class in [`ActivationClass::ALL`] order.
    pub sigma_dps: [[f32; SIGMA_KNOTS]; ACTIVATION_CLASSES],
    /// A start with more residual heat than this (°C, [`SwitchOn::residual_heat_celsius`]) is a
    /// warm restart.
    pub warm_above_celsius: f32,
    /// The calibrated envelope's lowest ambient, °C.
    pub ambient_min_celsius: f32,
    /// The calibrated envelope's highest ambient, °C.
    pub ambient_max_celsius: f32,
    /// What σ grows by per °C of ambient outside the envelope, °/s per °C.
    pub per_celsius_outside_dps: f32,
    /// Per axis, the most residual heat a calibration activation switched on with, °C: the
    /// tables' envelope ([`crate::Envelope::most_residual_heat_celsius`]); the corrector holds a
    /// larger heat there and flags it `HISTORY_OUT_OF_SPAN`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub most_residual_heat_celsius: [f32; AXES],
    /// What σ grows by per °C of residual heat beyond the most, °/s per °C.
    #[cfg_attr(feature = "serde", serde(default))]
    pub per_residual_celsius_beyond_dps: f32,
}

/// What [`Uncertainty::start`] decided at switch-on, per axis: plain data, 28 bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SigmaState {
    /// The activation's class per axis.
    pub class: [ActivationClass; AXES],
    /// How far the switch-on ambient lies outside the envelope per axis, °C (0 inside).
    pub outside_celsius: [f32; AXES],
    /// What σ grows by for the whole activation per axis, °/s: outside the ambients and beyond
    /// the residual heats of the calibration.
    pub widening_dps: [f32; AXES],
}

impl Uncertainty {
    /// Checks every value; the error names the field and where it sits.
    pub fn validate(&self) -> Result<(), Error> {
        let mut before: Option<u32> = None;
        for (k, &ms) in self.knots_ms.iter().enumerate() {
            let ordered = match before {
                None => ms == 0,
                Some(b) => ms > b,
            };
            if !ordered {
                return Err(Error::new(
                    "knots_ms",
                    Location::default().index(k),
                    Problem::NotIncreasing,
                ));
            }
            before = Some(ms);
        }
        for (c, row) in self.sigma_dps.iter().enumerate() {
            for (k, &sigma) in row.iter().enumerate() {
                non_negative("sigma_dps", Location::default().curve(c).point(k), sigma)?;
            }
        }
        non_negative(
            "warm_above_celsius",
            Location::default(),
            self.warm_above_celsius,
        )?;
        non_negative(
            "per_celsius_outside_dps",
            Location::default(),
            self.per_celsius_outside_dps,
        )?;
        non_negative(
            "per_residual_celsius_beyond_dps",
            Location::default(),
            self.per_residual_celsius_beyond_dps,
        )?;
        for (axis, &most) in self.most_residual_heat_celsius.iter().enumerate() {
            non_negative("most_residual_heat_celsius", Location::axis(axis), most)?;
        }
        for (field, value) in [
            ("ambient_min_celsius", self.ambient_min_celsius),
            ("ambient_max_celsius", self.ambient_max_celsius),
        ] {
            if !value.is_finite() {
                return Err(Error::new(field, Location::default(), Problem::NonFinite));
            }
        }
        if self.ambient_max_celsius < self.ambient_min_celsius {
            return Err(Error::new(
                "ambient_max_celsius",
                Location::default(),
                Problem::NotIncreasing,
            ));
        }
        Ok(())
    }

    /// The class and the distance outside the envelope (°C, ≥ 0, finite) of one axis's switch-on.
    pub fn classify(&self, switch_on: &SwitchOn) -> (ActivationClass, f32) {
        let class = if switch_on.residual_heat_celsius > self.warm_above_celsius {
            ActivationClass::WarmRestart
        } else {
            ActivationClass::Cold
        };
        let ambient = switch_on.ambient_celsius;
        // A non-finite ambient (no reading; the corrector refuses such a switch-on) is taken as
        // inside, so that σ stays finite.
        let outside = if ambient.is_finite() {
            (self.ambient_min_celsius - ambient)
                .max(ambient - self.ambient_max_celsius)
                .max(0.0)
        } else {
            0.0
        };
        (class, outside)
    }

    /// The state for an activation from each axis's switch-on: call it at switch-on with the
    /// estimates `power_on_after` makes (`SwitchOn::estimate` of the switch-on temperature and
    /// what was kept, before `power_on_after` overwrites it).
    #[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
    pub fn start(&self, switch_on: &[SwitchOn; AXES]) -> SigmaState {
        let mut state = SigmaState::default();
        for (((class, outside), widening), (switch_on, &most)) in state
            .class
            .iter_mut()
            .zip(&mut state.outside_celsius)
            .zip(&mut state.widening_dps)
            .zip(switch_on.iter().zip(&self.most_residual_heat_celsius))
        {
            (*class, *outside) = self.classify(switch_on);
            let beyond = heat_beyond(most, switch_on).unwrap_or(0.0);
            *widening = self.per_celsius_outside_dps * *outside
                + self.per_residual_celsius_beyond_dps * beyond;
        }
        state
    }

    /// σ of the residual bias per axis, °/s, at `since_power_on_ms`: beside each corrected sample.
    /// Only + − × ÷ and comparisons (no libm): the same bits on the host and on a Cortex-M4F. The
    /// knot search and the fraction are shared by the axes; each axis adds one interpolation.
    #[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
    pub fn sigma_dps(&self, state: &SigmaState, since_power_on_ms: u32) -> [f32; AXES] {
        let (k, fraction) = position(&self.knots_ms, since_power_on_ms);
        let mut out = [0.0; AXES];
        for ((sigma, class), widening) in out.iter_mut().zip(state.class).zip(state.widening_dps) {
            let curve = match class {
                ActivationClass::Cold => &self.sigma_dps[0],
                ActivationClass::WarmRestart => &self.sigma_dps[1],
            };
            let v0 = curve.get(k).copied().unwrap_or(0.0);
            let along = match fraction {
                Some(f) => {
                    let v1 = curve.get(k.saturating_add(1)).copied().unwrap_or(v0);
                    v0 + (v1 - v0) * f
                }
                None => v0,
            };
            *sigma = along + widening;
        }
        out
    }
}

/// Where `ms` falls among the knots: the knot before it and the fraction of the way to the next
/// one, or a knot whose value holds (after the last; unvalidated knots that do not increase).
#[allow(clippy::arithmetic_side_effects)] // f32 arithmetic; the u32 differences saturate.
fn position(knots_ms: &[u32; SIGMA_KNOTS], ms: u32) -> (usize, Option<f32>) {
    for (k, pair) in knots_ms.windows(2).enumerate() {
        if let [k0, k1] = *pair {
            if ms < k1 {
                let span = k1.saturating_sub(k0) as f32;
                let into = ms.saturating_sub(k0) as f32;
                return if span > 0.0 {
                    (k, Some(into / span))
                } else {
                    (k.saturating_add(1), None)
                };
            }
        }
    }
    (SIGMA_KNOTS - 1, None)
}

fn non_negative(field: &'static str, location: Location, value: f32) -> Result<(), Error> {
    if !value.is_finite() {
        return Err(Error::new(field, location, Problem::NonFinite));
    }
    if value < 0.0 {
        return Err(Error::new(field, location, Problem::Negative));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> Uncertainty {
        Uncertainty {
            knots_ms: [0, 2_000, 5_000, 10_000, 20_000, 40_000, 80_000, 160_000],
            sigma_dps: [
                [0.004, 0.003, 0.002, 0.002, 0.001, 0.001, 0.001, 0.001],
                [0.008, 0.006, 0.004, 0.003, 0.002, 0.002, 0.001, 0.001],
            ],
            warm_above_celsius: 0.5,
            ambient_min_celsius: 30.0,
            ambient_max_celsius: 40.0,
            per_celsius_outside_dps: 0.001,
            most_residual_heat_celsius: [3.0, 3.0, 1.0],
            per_residual_celsius_beyond_dps: 0.002,
        }
    }

    fn switch_on(ambient: f32, residual: f32) -> SwitchOn {
        SwitchOn {
            switch_on_celsius: ambient + residual,
            ambient_celsius: ambient,
            residual_heat_celsius: residual,
            remaining: 0.0,
            known: true,
        }
    }

    #[test]
    fn sigma_follows_the_knots_and_holds_after_the_last() {
        let u = example();
        u.validate().unwrap();
        let state = u.start(&[
            switch_on(33.0, 0.0),
            switch_on(33.0, 2.0),
            switch_on(33.0, 0.4),
        ]);
        assert_eq!(
            state.class,
            [
                ActivationClass::Cold,
                ActivationClass::WarmRestart,
                ActivationClass::Cold
            ]
        );
        assert_eq!(u.sigma_dps(&state, 0), [0.004, 0.008, 0.004]);
        let half = u.sigma_dps(&state, 1_000);
        assert!((half[0] - 0.0035).abs() < 1e-7 && (half[1] - 0.007).abs() < 1e-7);
        assert_eq!(u.sigma_dps(&state, 20_000)[1], 0.002);
        assert_eq!(u.sigma_dps(&state, u32::MAX), [0.001; 3]);
    }

    #[test]
    fn sigma_grows_outside_the_envelope_only() {
        let u = example();
        let state = u.start(&[
            switch_on(25.0, 0.0),
            switch_on(42.0, 0.0),
            switch_on(f32::NAN, 0.0),
        ]);
        assert_eq!(state.outside_celsius, [5.0, 2.0, 0.0]);
        let sigma = u.sigma_dps(&state, 200_000);
        assert!((sigma[0] - 0.006).abs() < 1e-7, "{sigma:?}");
        assert!((sigma[1] - 0.003).abs() < 1e-7, "{sigma:?}");
        assert_eq!(sigma[2], 0.001);
    }

    #[test]
    fn sigma_grows_beyond_the_calibrated_residual_heat_only() {
        let u = example();
        // Heats 2, 5 and 1.5 °C against the most 3, 3 and 1 °C: inside, 2 °C and 0.5 °C beyond.
        let state = u.start(&[
            switch_on(33.0, 2.0),
            switch_on(33.0, 5.0),
            switch_on(33.0, 1.5),
        ]);
        let sigma = u.sigma_dps(&state, 200_000);
        assert_eq!(sigma[0], 0.001);
        assert!((sigma[1] - 0.005).abs() < 1e-7, "{sigma:?}");
        assert!((sigma[2] - 0.002).abs() < 1e-7, "{sigma:?}");
        let mut unknown = switch_on(33.0, 5.0);
        unknown.known = false;
        let state = u.start(&[unknown; 3]);
        assert_eq!(
            u.sigma_dps(&state, 200_000),
            [0.001; 3],
            "nothing kept: no heat"
        );
    }

    #[test]
    fn invalid_values_are_named() {
        let mut u = example();
        u.knots_ms[3] = u.knots_ms[2];
        assert_eq!(u.validate().unwrap_err().field, "knots_ms");
        let mut u = example();
        u.knots_ms[0] = 1;
        assert_eq!(u.validate().unwrap_err().field, "knots_ms");
        let mut u = example();
        u.sigma_dps[1][4] = f32::NAN;
        assert_eq!(u.validate().unwrap_err().field, "sigma_dps");
        let mut u = example();
        u.ambient_max_celsius = 20.0;
        assert_eq!(u.validate().unwrap_err().field, "ambient_max_celsius");
        let mut u = example();
        u.most_residual_heat_celsius[2] = -1.0;
        assert_eq!(
            u.validate().unwrap_err().field,
            "most_residual_heat_celsius"
        );
        let mut u = example();
        u.per_residual_celsius_beyond_dps = f32::INFINITY;
        assert_eq!(
            u.validate().unwrap_err().field,
            "per_residual_celsius_beyond_dps"
        );
    }

    #[test]
    fn unvalidated_knots_never_panic() {
        let mut u = example();
        u.knots_ms = [5, 3, 3, 0, u32::MAX, 1, 2, 0];
        let state = u.start(&[switch_on(33.0, 1.0); AXES]);
        for ms in [0, 1, 3, 4, 5, 1_000, u32::MAX] {
            let _ = u.sigma_dps(&state, ms);
        }
    }
}
