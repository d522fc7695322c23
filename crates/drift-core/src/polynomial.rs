//! Baselines: bias as a polynomial of the absolute sensor temperature, with no heating dynamics.
//!
//! One type serves both baselines the project compares against: the paper's "standard" calibration
//! (a Lagrange polynomial through the bias at the calibration temperatures, converted by the fitter
//! to this form) and the PX4/ArduPilot practice (a least-squares 3rd-order polynomial per axis).

use heapless::Vec;

use crate::error::{check_finite, Error, Location, Problem};
use crate::flags::Flags;
use crate::model::{AxisModel, Model};
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
        let [low, high] = self.range_celsius;
        // `max`/`min` rather than `clamp`: `clamp` panics on an inverted range.
        let clamped = celsius.max(low).min(high);
        let outside =
            celsius.is_nan() || celsius < low - margin_celsius || celsius > high + margin_celsius;
        let half_span = 0.5 * (high - low);
        let x = (clamped - (low + half_span)) / half_span;
        let value = self
            .coefficients
            .iter()
            .rev()
            .fold(0.0_f32, |acc, &c| acc * x + c);
        (value, outside)
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

/// Per-axis run-time state of a polynomial baseline: its value at switch-on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PolynomialAxisState {
    at_switch_on_dps: f32,
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
        let (bias, outside) = self.evaluate(temperature_celsius, settings.ambient_margin_celsius);
        let flags = if outside {
            Flags::TEMPERATURE_OUT_OF_RANGE
        } else {
            Flags::NONE
        };
        // Split as initial bias + drift since switch-on, like the modified model, so the two report
        // comparable quantities.
        (bias - state.at_switch_on_dps, flags)
    }
}

/// A polynomial baseline for a whole unit.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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
