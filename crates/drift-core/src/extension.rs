//! The extended model: a few extra linear terms on top of the paper's tables, for the effects the
//! tables cannot know when the unit is used differently from its calibration (issue 6's closed
//! loop: the diagnosis names the effect, the fitter adds its term).
//!
//! Each term is a quantity the microcontroller computes per sample without heap — the axis's own
//! temperature rate from a first-order filter, an auxiliary input the firmware passes in (supply
//! voltage, an accelerometer axis), another axis's rise, the axis's own rise squared — centred on
//! its calibration mean and multiplied by a per-axis coefficient. The term values come from
//! [`ExtensionState::values`], which the fitter calls too, so firmware and fit compute them
//! identically.

use heapless::Vec;

use crate::error::{Error, Location, Problem};
use crate::AXES;

/// Most extra terms a model carries.
pub const MAX_TERMS: usize = 4;

/// Auxiliary inputs the firmware can pass per sample (e.g. supply voltage and three accelerometer
/// axes), by index.
pub const AUX_INPUTS: usize = 4;

/// What one extra term measures. Every kind is computed per axis from that axis's readings, except
/// [`Term::Aux`], which is the same input for every axis (each axis has its own coefficient).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Term {
    /// The axis's temperature rate, °C/s: `(T − T_filtered) / τ`, where `T_filtered` follows the
    /// temperature through a first-order low-pass of time constant `τ` (a filtered derivative
    /// that needs one float of state per axis and no sample history).
    TemperatureRate {
        /// The filter's time constant `τ`, milliseconds (> 0).
        time_constant_ms: u32,
    },
    /// Auxiliary input `input` (0 ..[`AUX_INPUTS`]) as the firmware passes it, in its own unit.
    Aux {
        /// Index into the auxiliary inputs.
        input: u8,
    },
    /// The rise since switch-on of another axis (0 = X, 1 = Y, 2 = Z), °C.
    AxisRise {
        /// The axis whose rise is read.
        axis: u8,
    },
    /// The axis's own rise since switch-on, squared, °C².
    RiseSquared,
}

/// One extra term: its kind, and per axis its centre (the term's calibration mean) and coefficient.
/// The axis's bias gains `coefficient · (value − centre)`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExtraTerm {
    /// What the term measures.
    pub term: Term,
    /// Per axis, the value the term is measured from (its calibration mean), in the term's unit.
    pub centre: [f32; AXES],
    /// Per axis, °/s per unit of the term (0 leaves that axis untouched).
    pub coefficient: [f32; AXES],
}

/// The extra terms of a model; empty for the paper's model as published.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Extension {
    /// At most [`MAX_TERMS`] terms.
    pub terms: Vec<ExtraTerm, MAX_TERMS>,
}

/// The term values of one sample: `values[axis][term]`, centred (value − centre). Terms past the
/// model's count are 0.
pub type TermValues = [[f32; MAX_TERMS]; AXES];

impl Extension {
    /// No extra terms.
    pub const NONE: Self = Self { terms: Vec::new() };

    /// Whether the model has no extra terms (the per-sample path then skips the extension).
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// Checks every term: known inputs and axes, positive time constants, finite numbers.
    pub fn validate(&self) -> Result<(), Error> {
        for (index, term) in self.terms.iter().enumerate() {
            let at = Location::default().index(index);
            let bad_index = match term.term {
                Term::TemperatureRate { time_constant_ms } => {
                    if time_constant_ms == 0 {
                        return Err(Error::new(
                            "term_time_constant_ms",
                            at,
                            Problem::NotPositive,
                        ));
                    }
                    // One filter per axis: every rate term reads it, so they must agree on τ.
                    let first = self.terms.iter().find_map(|t| match t.term {
                        Term::TemperatureRate { time_constant_ms } => Some(time_constant_ms),
                        _ => None,
                    });
                    if first != Some(time_constant_ms) {
                        return Err(Error::new("term_time_constant_ms", at, Problem::Mismatch));
                    }
                    None
                }
                Term::Aux { input } => {
                    (usize::from(input) >= AUX_INPUTS).then_some(("term_input", AUX_INPUTS))
                }
                Term::AxisRise { axis } => {
                    (usize::from(axis) >= AXES).then_some(("term_axis", AXES))
                }
                Term::RiseSquared => None,
            };
            if let Some((field, limit)) = bad_index {
                return Err(Error::new(
                    field,
                    at,
                    Problem::OutOfRange {
                        limit: u16::try_from(limit).unwrap_or(u16::MAX),
                    },
                ));
            }
            for (field, values) in [
                ("term_centre", term.centre),
                ("term_coefficient", term.coefficient),
            ] {
                if let Some(axis) = values.iter().position(|v| !v.is_finite()) {
                    return Err(Error::new(
                        field,
                        Location::axis(axis).index(index),
                        Problem::NonFinite,
                    ));
                }
            }
        }
        Ok(())
    }

    /// The extension's bias per axis for centred term `values`, °/s.
    pub fn bias(&self, values: &TermValues) -> [f32; AXES] {
        let mut bias = [0.0; AXES];
        for (axis, (bias, values)) in bias.iter_mut().zip(values).enumerate() {
            for (term, value) in self.terms.iter().zip(values) {
                *bias += term.coefficient.get(axis).copied().unwrap_or(0.0) * value;
            }
        }
        bias
    }
}

/// What the extension keeps between samples: the temperature filters and the time of the last
/// sample. Reset at every switch-on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExtensionState {
    /// Per axis, the temperature of the previous sample, °C.
    last_celsius: [f32; AXES],
    /// Per axis, how far the low-passed temperature lags the temperature, °C (for
    /// [`Term::TemperatureRate`]). Kept as the lag, not as the low-passed temperature: at 1 kHz a
    /// step of the filter moves it by ~1e-5 °C, below an f32's resolution at 30 °C (2e-6 °C)
    /// but not at the lag's size (~0.05 °C).
    lag_celsius: [f32; AXES],
    /// Time of the previous sample, ms since switch-on.
    last_ms: u32,
    /// The filter's step for the last (τ, Δt): samples come at a fixed rate, so its divisions are
    /// done once, not per sample.
    step: Option<FilterStep>,
}

/// The filter's per-sample constants for one time constant and one time step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct FilterStep {
    /// τ, ms.
    tau_ms: u32,
    /// Δt, ms.
    elapsed_ms: u32,
    /// τ / (τ + Δt): how much of the lag is left after the step.
    keep: f32,
    /// 1000 / τ: lag (°C) to rate (°C/s).
    per_second: f32,
}

impl FilterStep {
    fn new(tau_ms: u32, elapsed_ms: u32) -> Self {
        // Both below 2^24 in practice (τ is seconds, Δt milliseconds to seconds), so exact.
        let (tau, elapsed) = (tau_ms as f32, elapsed_ms as f32);
        Self {
            tau_ms,
            elapsed_ms,
            keep: tau / (tau + elapsed),
            per_second: 1000.0 / tau,
        }
    }
}

/// One sample's inputs to the extension, per axis unless said otherwise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TermInputs {
    /// Time since switch-on, ms.
    pub since_power_on_ms: u32,
    /// Temperature, °C.
    pub celsius: [f32; AXES],
    /// Rise since switch-on, °C.
    pub rise_celsius: [f32; AXES],
    /// The auxiliary inputs (shared by the axes).
    pub aux: [f32; AUX_INPUTS],
}

impl ExtensionState {
    /// The state at switch-on: the filters start at the switch-on temperatures (rate 0).
    pub fn power_on(switch_on_celsius: [f32; AXES]) -> Self {
        Self {
            last_celsius: switch_on_celsius,
            lag_celsius: [0.0; AXES],
            last_ms: 0,
            step: None,
        }
    }

    /// Advances the filter to this sample and returns the centred term values. Non-finite inputs
    /// give non-finite values for the terms that read them (the corrector then holds and flags);
    /// a non-finite temperature leaves the filter where it was.
    pub fn values(&mut self, extension: &Extension, inputs: &TermInputs) -> TermValues {
        let rates = self.advance(extension, inputs);
        let mut values = [[0.0; MAX_TERMS]; AXES];
        for (t, term) in extension.terms.iter().enumerate() {
            let raw = term_raw(term.term, &rates, inputs);
            for ((axis_values, raw), centre) in values.iter_mut().zip(raw).zip(term.centre) {
                if let Some(value) = axis_values.get_mut(t) {
                    *value = raw - centre;
                }
            }
        }
        values
    }

    /// Advances the filter to this sample and returns the extension's bias per axis, °/s: the
    /// same bits as [`Extension::bias`] of [`Self::values`], without the value matrix. Non-finite
    /// when a term's value is (the corrector then holds and flags).
    #[inline]
    pub(crate) fn bias(&mut self, extension: &Extension, inputs: &TermInputs) -> [f32; AXES] {
        let rates = self.advance(extension, inputs);
        let mut bias = [0.0; AXES];
        for term in &extension.terms {
            let raw = term_raw(term.term, &rates, inputs);
            for (((bias, raw), centre), coefficient) in bias
                .iter_mut()
                .zip(raw)
                .zip(term.centre)
                .zip(term.coefficient)
            {
                *bias += coefficient * (raw - centre);
            }
        }
        bias
    }

    /// Steps the temperature filters to this sample; returns each axis's temperature rate, °C/s
    /// (NaN when no term reads it).
    #[inline(always)]
    fn advance(&mut self, extension: &Extension, inputs: &TermInputs) -> [f32; AXES] {
        let elapsed_ms = inputs.since_power_on_ms.saturating_sub(self.last_ms);
        self.last_ms = inputs.since_power_on_ms;
        // Validation makes every rate term agree on τ; the first one's is used.
        let Some(tau_ms) = extension.terms.iter().find_map(|t| match t.term {
            Term::TemperatureRate { time_constant_ms } => Some(time_constant_ms),
            _ => None,
        }) else {
            return [f32::NAN; AXES];
        };
        let step = match self.step {
            Some(step) if step.tau_ms == tau_ms && step.elapsed_ms == elapsed_ms => step,
            _ => FilterStep::new(tau_ms, elapsed_ms),
        };
        self.step = Some(step);
        let mut rates = [f32::NAN; AXES];
        for (((rate, celsius), last), lag) in rates
            .iter_mut()
            .zip(inputs.celsius)
            .zip(&mut self.last_celsius)
            .zip(&mut self.lag_celsius)
        {
            // Backward Euler of the first-order low-pass T_f' = (T − T_f)/τ, written for the
            // lag d = T − T_f: d ← (d + ΔT) · τ/(τ + Δt); the rate estimate is d/τ. Stable for
            // any step, no exp(); ΔT of two close readings is exact in f32.
            let next = (*lag + (celsius - *last)) * step.keep;
            *rate = next * step.per_second;
            if next.is_finite() {
                *lag = next;
                *last = celsius;
            }
        }
        rates
    }
}

/// A term's uncentred value per axis.
#[inline(always)]
fn term_raw(term: Term, rates: &[f32; AXES], inputs: &TermInputs) -> [f32; AXES] {
    match term {
        Term::TemperatureRate { .. } => *rates,
        Term::Aux { input } => {
            [inputs
                .aux
                .get(usize::from(input))
                .copied()
                .unwrap_or(f32::NAN); AXES]
        }
        Term::AxisRise { axis } => {
            [inputs
                .rise_celsius
                .get(usize::from(axis))
                .copied()
                .unwrap_or(f32::NAN); AXES]
        }
        Term::RiseSquared => inputs.rise_celsius.map(|rise| rise * rise),
    }
}
