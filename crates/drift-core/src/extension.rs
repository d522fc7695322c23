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
        }
    }

    /// Advances the filter to this sample and returns the centred term values. Non-finite inputs
    /// give non-finite values for the terms that read them (the corrector then holds and flags);
    /// a non-finite temperature leaves the filter where it was.
    pub fn values(&mut self, extension: &Extension, inputs: &TermInputs) -> TermValues {
        let elapsed_ms = self.elapsed_ms(inputs.since_power_on_ms);
        // Validation makes every rate term agree on τ; the first one's is used.
        let rates = extension
            .terms
            .iter()
            .find_map(|t| match t.term {
                Term::TemperatureRate { time_constant_ms } => Some(time_constant_ms),
                _ => None,
            })
            .map_or([f32::NAN; AXES], |tau_ms| {
                self.step(tau_ms, elapsed_ms, &inputs.celsius)
            });
        let mut values = [[0.0; MAX_TERMS]; AXES];
        for (t, term) in extension.terms.iter().enumerate() {
            let raw = match term.term {
                Term::TemperatureRate { .. } => rates,
                Term::Aux { input } => [shared(&inputs.aux, input); AXES],
                Term::AxisRise { axis } => [shared(&inputs.rise_celsius, axis); AXES],
                Term::RiseSquared => inputs.rise_celsius.map(|rise| rise * rise),
            };
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
    #[inline(always)]
    pub(crate) fn bias(
        &mut self,
        extension: &Extension,
        since_power_on_ms: u32,
        celsius: &[f32; AXES],
        rise_celsius: &[f32; AXES],
        aux: &[f32; AUX_INPUTS],
    ) -> [f32; AXES] {
        let elapsed_ms = self.elapsed_ms(since_power_on_ms);
        let mut rates = None;
        let [mut x, mut y, mut z] = [0.0_f32; AXES];
        for term in &extension.terms {
            let ([cx, cy, cz], [mx, my, mz]) = (term.coefficient, term.centre);
            // Summed in each arm rather than after a match that returns the values: measured 12
            // instructions per sample fewer on the Cortex-M4 (docs/embedded.md).
            let mut add = |[vx, vy, vz]: [f32; AXES]| {
                x += cx * (vx - mx);
                y += cy * (vy - my);
                z += cz * (vz - mz);
            };
            match term.term {
                // The filter steps once per sample, at the first rate term (validation makes
                // every rate term agree on τ), as `values` does.
                Term::TemperatureRate { time_constant_ms } => {
                    add(*rates
                        .get_or_insert_with(|| self.step(time_constant_ms, elapsed_ms, celsius)))
                }
                Term::Aux { input } => add([shared(aux, input); AXES]),
                Term::AxisRise { axis } => add([shared(rise_celsius, axis); AXES]),
                Term::RiseSquared => add(rise_celsius.map(|rise| rise * rise)),
            }
        }
        [x, y, z]
    }

    /// Time since the previous sample, ms; remembers this sample's time.
    #[inline(always)]
    fn elapsed_ms(&mut self, since_power_on_ms: u32) -> u32 {
        let elapsed_ms = since_power_on_ms.saturating_sub(self.last_ms);
        self.last_ms = since_power_on_ms;
        elapsed_ms
    }

    /// Steps the temperature filters of time constant `tau_ms` by `elapsed_ms` to `celsius`;
    /// returns each axis's temperature rate, °C/s.
    #[inline(always)]
    fn step(&mut self, tau_ms: u32, elapsed_ms: u32, celsius: &[f32; AXES]) -> [f32; AXES] {
        // Both below 2^24 in practice (τ is seconds, Δt milliseconds to seconds), so exact. Two
        // divisions per sample rather than a cache keyed by (τ, Δt): the cache cost 20 bytes of
        // state and, counted in instructions, more than it saved.
        let (tau, elapsed) = (tau_ms as f32, elapsed_ms as f32);
        let keep = tau / (tau + elapsed);
        let per_second = 1000.0 / tau;
        let mut rates = [f32::NAN; AXES];
        for (((rate, celsius), last), lag) in rates
            .iter_mut()
            .zip(celsius)
            .zip(&mut self.last_celsius)
            .zip(&mut self.lag_celsius)
        {
            // Backward Euler of the first-order low-pass T_f' = (T − T_f)/τ, written for the
            // lag d = T − T_f: d ← (d + ΔT) · τ/(τ + Δt); the rate estimate is d/τ. Stable for
            // any step, no exp(); ΔT of two close readings is exact in f32.
            let next = (*lag + (celsius - *last)) * keep;
            *rate = next * per_second;
            if next.is_finite() {
                *lag = next;
                *last = *celsius;
            }
        }
        rates
    }
}

/// A term that reads the same input for every axis: input `index` of `inputs` (NaN if missing).
#[inline(always)]
fn shared<const N: usize>(inputs: &[f32; N], index: u8) -> f32 {
    inputs.get(usize::from(index)).copied().unwrap_or(f32::NAN)
}
