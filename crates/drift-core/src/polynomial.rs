//! Baselines: bias as a polynomial of the absolute sensor temperature, with no heating dynamics.
//!
//! Two forms, as practitioners use them:
//!
//! - absolute ([`PolynomialTables`]): `bias = p(T)`. The paper's "standard" calibration (a Lagrange
//!   polynomial through the bias at the calibration temperatures) and the PX4/ArduPilot practice (a
//!   least-squares 3rd-order polynomial per axis).
//! - relative to the switch-on ([`RelativePolynomialTables`]): `bias = q(T_on) + p(T) − p(T_on)`,
//!   the turn-on bias `q(T_on)` registered at switch-on from the calibration (as the paper's model
//!   takes its initial bias) and the drift after it from a polynomial fitted on the drift since
//!   switch-on, so each activation's random turn-on bias does not bend `p`.

use heapless::Vec;

use crate::error::{check_finite, Error, Location, Problem};
use crate::flags::Flags;
use crate::model::{AxisModel, ConstDefault, Model};
use crate::settings::Settings;
use crate::AXES;

/// Most coefficients a polynomial may have (degree 7).
pub const MAX_POLYNOMIAL_COEFFICIENTS: usize = 8;

/// Bias of one axis as a polynomial of the sensor temperature.
///
/// `bias(T) = Σ_i coefficients[i] · x^i` with `x = (T − mid) / half_span` mapping `range_celsius` onto
/// [−1, 1], which keeps f32 evaluation well conditioned. Outside `range_celsius` the polynomial is
/// evaluated at the nearest end (clamp) and, beyond the ambient margin, flagged: polynomials
/// extrapolate badly.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PolynomialAxis {
    /// Temperature range the polynomial was fitted over, `[low, high]`, °C.
    pub range_celsius: [f32; 2],
    /// Coefficients in the normalised variable `x`, constant term first, °/s.
    pub coefficients: Vec<f32, MAX_POLYNOMIAL_COEFFICIENTS>,
}

impl PolynomialAxis {
    /// The polynomial at `celsius` (clamped to the fitted range), and whether that clamp went beyond
    /// `margin_celsius`.
    pub fn evaluate(&self, celsius: f32, margin_celsius: f32) -> (f32, bool) {
        let span = Span::new(self.range_celsius, margin_celsius);
        let value = horner(&self.coefficients, span.normalised(celsius));
        (value, span.outside(celsius))
    }

    /// The polynomial at `celsius`, continued beyond the fitted range along its tangent at the
    /// nearer end (a NaN reads as the low end, as in [`Self::evaluate`]), and whether `celsius`
    /// lies beyond `margin_celsius`. For a value read once per activation from a fit that must
    /// keep the temperature's trend where a unit is used outside its calibration (a clamp holds
    /// the end's value; a polynomial's own curvature swings).
    pub fn continued(&self, celsius: f32, margin_celsius: f32) -> (f32, bool) {
        let span = Span::new(self.range_celsius, margin_celsius);
        let edge = span.normalised(celsius);
        let x = (celsius - span.mid) / span.half_span;
        let (mut value, mut slope) = (0.0_f32, 0.0_f32);
        for &c in self.coefficients.iter().rev() {
            slope = slope * edge + value;
            value = value * edge + c;
        }
        // Inside the range x − edge is exactly 0 (the same arithmetic as `normalised`); a NaN or
        // infinite reading takes no tangent.
        let beyond = x - edge;
        let beyond = if beyond.is_finite() { beyond } else { 0.0 };
        (value + slope * beyond, span.outside(celsius))
    }

    /// Checks this axis's polynomial; `at` names the axis in errors.
    pub fn validate(&self, at: Location) -> Result<(), Error> {
        check_finite("range_celsius", at, self.range_celsius)?;
        let [low, high] = self.range_celsius;
        if high <= low {
            return Err(Error::new(
                "range_celsius",
                at.index(1),
                Problem::NotIncreasing,
            ));
        }
        if self.coefficients.is_empty() {
            return Err(Error::new("coefficients", at, Problem::Empty));
        }
        check_finite("coefficients", at, self.coefficients.iter().copied())
    }
}

/// The fitted range and what `evaluate` derives from it. Shared by the switch-on and the per-sample
/// evaluation, so both give the same bits.
#[derive(Clone, Copy)]
struct Span {
    low: f32,
    high: f32,
    mid: f32,
    half_span: f32,
    margin_celsius: f32,
}

impl Span {
    #[inline(always)]
    fn new([low, high]: [f32; 2], margin_celsius: f32) -> Self {
        let half_span = 0.5 * (high - low);
        Self {
            low,
            high,
            mid: low + half_span,
            half_span,
            margin_celsius,
        }
    }

    /// `celsius` clamped to the range and mapped onto [−1, 1]. The clamp compares rather than
    /// calling `max`/`min`: the same value (NaN reads as the low end; only the sign of a zero
    /// could differ, which the subtraction of `mid ≠ 0` erases). (`clamp` would panic on an
    /// inverted range.)
    #[inline(always)]
    fn normalised(&self, celsius: f32) -> f32 {
        let above_low = if celsius > self.low {
            celsius
        } else {
            self.low
        };
        let clamped = if above_low < self.high {
            above_low
        } else {
            self.high
        };
        (clamped - self.mid) / self.half_span
    }

    /// Whether `celsius` lies outside the range by more than the margin (or is NaN).
    #[inline(always)]
    fn outside(&self, celsius: f32) -> bool {
        celsius.is_nan()
            || celsius < self.low - self.margin_celsius
            || celsius > self.high + self.margin_celsius
    }
}

/// Per-axis run-time state of a polynomial baseline: its value at switch-on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PolynomialAxisState {
    at_switch_on_dps: f32,
}

impl ConstDefault for PolynomialAxisState {
    const DEFAULT: Self = Self {
        at_switch_on_dps: 0.0,
    };
}

impl AxisModel for PolynomialAxis {
    type State = PolynomialAxisState;

    fn power_on(
        &self,
        settings: &Settings,
        switch_on_celsius: f32,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        let (bias, outside) = self.evaluate(switch_on_celsius, settings.ambient_margin_celsius);
        state.at_switch_on_dps = bias;
        let flags = if outside {
            Flags::TEMPERATURE_OUT_OF_RANGE
        } else {
            Flags::NONE
        };
        (bias, flags)
    }

    fn drift(
        &self,
        settings: &Settings,
        state: &mut Self::State,
        _since_power_on_ms: u32,
        temperature_celsius: f32,
        _rise_celsius: f32,
    ) -> (f32, Flags) {
        // Split as initial bias + drift since switch-on, like the modified model, so the two report
        // comparable quantities.
        drift_at(
            Span::new(self.range_celsius, settings.ambient_margin_celsius),
            state.at_switch_on_dps,
            temperature_celsius,
            &self.coefficients,
        )
    }

    fn drift_of_temperatures(
        &self,
        settings: &Settings,
        state: &Self::State,
        celsius: &[f32],
        drift: &mut [f32],
        model_flags: &mut [Flags],
    ) -> bool {
        drifts_at(
            Span::new(self.range_celsius, settings.ambient_margin_celsius),
            state.at_switch_on_dps,
            &self.coefficients,
            celsius,
            drift,
            model_flags,
        );
        true
    }
}

/// The drift at `celsius` (the polynomial minus its value at switch-on) and the flag.
#[inline(always)]
fn drift_at(span: Span, at_switch_on_dps: f32, celsius: f32, coefficients: &[f32]) -> (f32, Flags) {
    let drift = horner(coefficients, span.normalised(celsius)) - at_switch_on_dps;
    let flags = if span.outside(celsius) {
        Flags::TEMPERATURE_OUT_OF_RANGE
    } else {
        Flags::NONE
    };
    (drift, flags)
}

/// Temperatures [`drifts_at`] takes at a time: four SSE vectors of f32, which stay in registers
/// through the whole polynomial.
const LANES: usize = 16;

/// [`drift_at`] for each of `celsius`, with the same operations in the same order (the same bits),
/// [`LANES`] temperatures at a time: Horner's scheme coefficient by coefficient across the lanes,
/// so that each step is one vector operation. A remainder shorter than `LANES` goes one by one.
fn drifts_at(
    span: Span,
    at_switch_on_dps: f32,
    coefficients: &[f32],
    celsius: &[f32],
    drift: &mut [f32],
    model_flags: &mut [Flags],
) {
    let mut celsius = celsius.chunks_exact(LANES);
    let mut drift = drift.chunks_exact_mut(LANES);
    let mut model_flags = model_flags.chunks_exact_mut(LANES);
    for ((celsius, drift), model_flags) in (&mut celsius).zip(&mut drift).zip(&mut model_flags) {
        let mut x = [0.0_f32; LANES];
        for (x, &celsius) in x.iter_mut().zip(celsius) {
            *x = span.normalised(celsius);
        }
        let mut value = [0.0_f32; LANES];
        for &c in coefficients.iter().rev() {
            for (value, &x) in value.iter_mut().zip(&x) {
                *value = *value * x + c;
            }
        }
        let answers = drift.iter_mut().zip(model_flags.iter_mut());
        for ((drift, flags), (&value, &celsius)) in answers.zip(value.iter().zip(celsius)) {
            *drift = value - at_switch_on_dps;
            *flags = if span.outside(celsius) {
                Flags::TEMPERATURE_OUT_OF_RANGE
            } else {
                Flags::NONE
            };
        }
    }
    let rest = drift.into_remainder().iter_mut();
    let rest = rest.zip(model_flags.into_remainder().iter_mut());
    for ((drift, flags), &celsius) in rest.zip(celsius.remainder()) {
        (*drift, *flags) = drift_at(span, at_switch_on_dps, celsius, coefficients);
    }
}

/// A polynomial at `x`, constant term first: Horner's scheme from the highest coefficient. The
/// one formula of the switch-on and the per-sample evaluation ([`drifts_at`] repeats it lane by
/// lane).
#[inline(always)]
fn horner(coefficients: &[f32], x: f32) -> f32 {
    coefficients
        .iter()
        .rev()
        .fold(0.0_f32, |acc, &c| acc * x + c)
}

/// A polynomial baseline for a whole unit.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct PolynomialTables {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One polynomial per axis (X, Y, Z).
    pub axes: [PolynomialAxis; AXES],
}

impl PolynomialTables {
    /// The validating constructor.
    pub fn try_new(settings: Settings, axes: [PolynomialAxis; AXES]) -> Result<Self, Error> {
        let tables = Self { settings, axes };
        tables.validate()?;
        Ok(tables)
    }
}

impl Model for PolynomialTables {
    type Axis = PolynomialAxis;

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn axes(&self) -> &[Self::Axis; AXES] {
        &self.axes
    }

    fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        for (axis, polynomial) in self.axes.iter().enumerate() {
            polynomial.validate(Location::axis(axis))?;
        }
        Ok(())
    }
}

/// One axis of the baseline relative to the switch-on: `bias = q(T_on) + p(T) − p(T_on)`.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RelativePolynomialAxis {
    /// `p`: the drift since switch-on is `p(T) − p(T_on)` (its constant term cancels).
    pub drift: PolynomialAxis,
    /// `q`: the turn-on bias as a polynomial of the switch-on temperature.
    pub turn_on: PolynomialAxis,
}

impl RelativePolynomialAxis {
    /// Checks both polynomials; `at` names the axis in errors.
    pub fn validate(&self, at: Location) -> Result<(), Error> {
        self.drift.validate(at)?;
        self.turn_on.validate(at)
    }
}

impl AxisModel for RelativePolynomialAxis {
    type State = PolynomialAxisState;

    fn power_on(
        &self,
        settings: &Settings,
        switch_on_celsius: f32,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        let margin = settings.ambient_margin_celsius;
        let (bias, outside) = self.turn_on.evaluate(switch_on_celsius, margin);
        state.at_switch_on_dps = self.drift.evaluate(switch_on_celsius, margin).0;
        let flags = if outside {
            Flags::TEMPERATURE_OUT_OF_RANGE
        } else {
            Flags::NONE
        };
        (bias, flags)
    }

    fn drift(
        &self,
        settings: &Settings,
        state: &mut Self::State,
        _since_power_on_ms: u32,
        temperature_celsius: f32,
        _rise_celsius: f32,
    ) -> (f32, Flags) {
        drift_at(
            Span::new(self.drift.range_celsius, settings.ambient_margin_celsius),
            state.at_switch_on_dps,
            temperature_celsius,
            &self.drift.coefficients,
        )
    }

    fn drift_of_temperatures(
        &self,
        settings: &Settings,
        state: &Self::State,
        celsius: &[f32],
        drift: &mut [f32],
        model_flags: &mut [Flags],
    ) -> bool {
        // `drift` is `p`'s own drift since switch-on.
        self.drift
            .drift_of_temperatures(settings, state, celsius, drift, model_flags)
    }
}

/// The baseline relative to the switch-on for a whole unit.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RelativePolynomialTables {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One pair of polynomials per axis (X, Y, Z).
    pub axes: [RelativePolynomialAxis; AXES],
}

impl Model for RelativePolynomialTables {
    type Axis = RelativePolynomialAxis;

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn axes(&self) -> &[Self::Axis; AXES] {
        &self.axes
    }

    fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        for (axis, pair) in self.axes.iter().enumerate() {
            pair.validate(Location::axis(axis))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(range: [f32; 2], coefficients: &[f32]) -> PolynomialAxis {
        PolynomialAxis {
            range_celsius: range,
            coefficients: Vec::from_slice(coefficients).unwrap_or_default(),
        }
    }

    /// The turn-on bias comes from `q`, the drift after it from `p`: neither from the other.
    #[test]
    fn the_relative_form_takes_its_turn_on_bias_from_q_and_its_drift_from_p() {
        let settings = Settings::default();
        let pair = RelativePolynomialAxis {
            // p(T) = 0.5 + 0.1·x over [20, 40]: x = (T − 30) / 10.
            drift: axis([20.0, 40.0], &[0.5, 0.1]),
            // q(T_on) = 0.02 everywhere.
            turn_on: axis([20.0, 40.0], &[0.02]),
        };
        let mut state = PolynomialAxisState::default();
        let (bias, flags) = pair.power_on(&settings, 30.0, &mut state);
        assert_eq!((bias, flags), (0.02, Flags::NONE));
        let (drift, flags) = pair.drift(&settings, &mut state, 0, 35.0, 5.0);
        assert!((drift - 0.05).abs() < 1e-6, "{drift}");
        assert_eq!(flags, Flags::NONE);
        // Beyond q's range by more than the margin: flagged, clamped.
        let (bias, flags) = pair.power_on(&settings, 45.0, &mut state);
        assert_eq!((bias, flags), (0.02, Flags::TEMPERATURE_OUT_OF_RANGE));
    }
}
