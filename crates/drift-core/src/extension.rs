//! The extended model: a few extra linear terms on top of the paper's tables, for the effects the
//! tables cannot know when the unit is used differently from its calibration (the closed
//! loop: the diagnosis names the effect, the fitter adds its term).
//!
//! Each term is a quantity the microcontroller computes per sample without heap — the axis's own
//! temperature rate from a first-order filter, an auxiliary input the firmware passes in (supply
//! voltage, an accelerometer axis) through a first-order low-pass, another axis's rise, the axis's
//! own rise squared — centred on
//! its calibration mean and multiplied by a per-axis coefficient. The term values come from
//! [`ExtensionState::values`], which the fitter calls too, so firmware and fit compute them
//! identically.

use heapless::Vec;

use crate::error::{Error, Location, Problem};
use crate::history::SwitchOn;
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
    /// Auxiliary input `input` (0 ..[`AUX_INPUTS`]) in its own unit, through a first-order
    /// low-pass of time constant `time_constant_ms` (backward Euler, like the rate filter; one
    /// float of state per term). A recorded channel's sample noise would otherwise pass straight
    /// into the correction. The filter starts at the first finite input after switch-on and, until
    /// `time_constant_ms` has passed, is the time-weighted mean of the inputs so far (its time
    /// constant grows with the time since switch-on), so the first reading's noise does not linger.
    /// A non-finite input leaves the filter where it was (the term holds, flagged); before the
    /// first finite input the term is 0.
    Aux {
        /// Index into the auxiliary inputs.
        input: u8,
        /// The low-pass's time constant, milliseconds; 0 passes the input through unfiltered
        /// (also what JSON tables without the field mean).
        #[cfg_attr(feature = "serde", serde(default))]
        time_constant_ms: u32,
    },
    /// The rise since switch-on of another axis (0 = X, 1 = Y, 2 = Z), °C.
    AxisRise {
        /// The axis whose rise is read.
        axis: u8,
    },
    /// The axis's own rise since switch-on, squared, °C².
    RiseSquared,
    /// Auxiliary input `input`, low-passed as [`Term::Aux`] is, times the axis's own rise since
    /// switch-on (input unit × °C): a sensitivity to the input that grows as the unit heats (a
    /// g-sensitivity or supply sensitivity with a temperature coefficient of its own). 0 before
    /// the input's first finite value.
    AuxTimesRise {
        /// Index into the auxiliary inputs.
        input: u8,
        /// The input's low-pass time constant, milliseconds (0: unfiltered).
        time_constant_ms: u32,
    },
}

/// One extra term: its kind, and per axis its centre (the term's calibration mean) and coefficient.
/// The axis's bias gains `coefficient · (value − centre)`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ExtraTerm {
    /// What the term measures.
    pub term: Term,
    /// Per axis, the value the term is measured from (its calibration mean), in the term's unit.
    pub centre: [f32; AXES],
    /// Per axis, °/s per unit of the term (0 leaves that axis untouched).
    pub coefficient: [f32; AXES],
}

/// One axis's temperature rate at switch-on, from what firmware knows then: where
/// [`Term::TemperatureRate`]'s filter starts.
///
/// A filter started at rest reads a rate of 0 at every switch-on, while the unit's own heating
/// starts at once (the temperature sensor sits on the heated ASIC: ~0.15 °C/s in the simulator)
/// and, after a short off-time, the unit is still cooling by an amount that depends on the
/// off-time. The first seconds of the estimate are then wrong, partly by a history-dependent
/// amount, and the drift curves, which start from the first seconds' bias, carry that error as an
/// offset the tables spread into a ramp (docs/closed-loop.md). The rate at
/// switch-on is
/// `heating − residual_heat · (cooling_per_second + cooling_per_second_per_remaining · remaining)`
/// ([`SwitchOn`]): a unit cools faster per °C while the fast part of its heat is still there
/// (`remaining`, the fraction of the switch-off heat left, is high after a short off-time), which
/// needs no clock. A start with no history known is taken as cold: the heating alone.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SwitchOnRate {
    /// The rate of a cold start at switch-on, °C/s.
    pub heating_celsius_per_s: f32,
    /// Cooling rate per °C of residual heat once the fast part of the heat has gone
    /// (`remaining` → 0), 1/s (≥ 0).
    pub cooling_per_second: f32,
    /// How much faster per unit of `remaining`, 1/s (`cooling_per_second` + it ≥ 0: a unit never
    /// warms itself while off).
    pub cooling_per_second_per_remaining: f32,
}

impl SwitchOnRate {
    /// Start the rate filter at rest, whatever the history.
    pub const AT_REST: Self = Self {
        heating_celsius_per_s: 0.0,
        cooling_per_second: 0.0,
        cooling_per_second_per_remaining: 0.0,
    };

    /// The sensor's temperature rate at `switch_on`, °C/s.
    pub fn rate(&self, switch_on: &SwitchOn) -> f32 {
        let per_second =
            self.cooling_per_second + self.cooling_per_second_per_remaining * switch_on.remaining;
        let rate = self.heating_celsius_per_s - switch_on.residual_heat_celsius * per_second;
        if rate.is_finite() {
            rate
        } else {
            0.0
        }
    }

    fn validate(&self, axis: usize) -> Result<(), Error> {
        let at = Location::axis(axis);
        let values = [
            self.heating_celsius_per_s,
            self.cooling_per_second,
            self.cooling_per_second_per_remaining,
        ];
        if values.iter().any(|v| !v.is_finite()) {
            return Err(Error::new("switch_on_rate", at, Problem::NonFinite));
        }
        // Over the whole range of `remaining` (0 ..= 1) the cooling per °C stays ≥ 0.
        if self.cooling_per_second < 0.0
            || self.cooling_per_second + self.cooling_per_second_per_remaining < 0.0
        {
            return Err(Error::new("switch_on_rate", at, Problem::Negative));
        }
        Ok(())
    }
}

/// The extra terms of a model; empty for the paper's model as published.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Extension {
    /// At most [`MAX_TERMS`] terms.
    pub terms: Vec<ExtraTerm, MAX_TERMS>,
    /// Per axis, where the temperature-rate filter starts at a switch-on (a plain
    /// [`crate::CorrectorState::power_on`] knows no history: a cold start, the heating alone).
    /// Unused without a [`Term::TemperatureRate`]. JSON tables without the field start at rest.
    #[cfg_attr(feature = "serde", serde(default))]
    pub switch_on_rate: [SwitchOnRate; AXES],
}

/// The term values of one sample: `values[axis][term]`, centred (value − centre). Terms past the
/// model's count are 0.
pub type TermValues = [[f32; MAX_TERMS]; AXES];

impl Extension {
    /// No extra terms.
    pub const NONE: Self = Self {
        terms: Vec::new(),
        switch_on_rate: [SwitchOnRate::AT_REST; AXES],
    };

    /// Whether the model has no extra terms (the per-sample path then skips the extension).
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// Checks every term: known inputs and axes, positive time constants, finite numbers; and the
    /// switch-on rate: finite, its cooling never a warming.
    pub fn validate(&self) -> Result<(), Error> {
        for (axis, start) in self.switch_on_rate.iter().enumerate() {
            start.validate(axis)?;
        }
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
                Term::Aux { input, .. } | Term::AuxTimesRise { input, .. } => {
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

/// What the extension keeps between samples: the temperature-rate filters, the auxiliary inputs'
/// filters and the time of the last sample. Reset at every switch-on. Plain data (32 bytes): copy
/// it to persist, restore it to resume.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ExtensionState {
    /// Per axis, the rise since switch-on through the rate filter's first-order low-pass, °C (for
    /// [`Term::TemperatureRate`]); at switch-on `−rate · τ` for the [`SwitchOnRate`] it starts
    /// from, so that its first estimate is that rate. The rise rather than the temperature: the
    /// filter needs no previous reading, and f32 resolves a rise (~5 °C: 5e-7 °C) six times finer
    /// than a temperature (~30 °C: 2e-6 °C), so the rate's rounding stays below 1e-5 °C/s at
    /// 1 kHz.
    filtered_rise: [f32; AXES],
    /// Per term, the low-passed auxiliary input ([`Term::Aux`], [`Term::AuxTimesRise`]; unused by
    /// other kinds): NaN until the first finite input, then held through non-finite ones.
    aux: [f32; MAX_TERMS],
    /// Time of the previous sample, ms since switch-on.
    last_ms: u32,
}

/// Bit for bit: the auxiliary filters start as NaN, and a state must equal its copy.
impl PartialEq for ExtensionState {
    fn eq(&self, other: &Self) -> bool {
        let bits = |state: &Self| {
            let floats = state.filtered_rise.into_iter().chain(state.aux);
            floats.map(f32::to_bits).chain([state.last_ms])
        };
        bits(self).eq(bits(other))
    }
}

impl Default for ExtensionState {
    fn default() -> Self {
        Self::POWER_ON
    }
}

/// One sample's inputs to the extension, per axis unless said otherwise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TermInputs {
    /// Time since switch-on, ms.
    pub since_power_on_ms: u32,
    /// Rise since switch-on, °C (finite: the corrector passes the last good reading's).
    pub rise_celsius: [f32; AXES],
    /// The auxiliary inputs (shared by the axes).
    pub aux: [f32; AUX_INPUTS],
}

impl ExtensionState {
    /// The state at switch-on: the rate filters at rise 0 (rate 0), the auxiliary filters waiting
    /// for their first finite input.
    pub const POWER_ON: Self = Self {
        filtered_rise: [0.0; AXES],
        aux: [f32::NAN; MAX_TERMS],
        last_ms: 0,
    };

    /// The state at switch-on ([`Self::POWER_ON`]).
    pub fn power_on() -> Self {
        Self::POWER_ON
    }

    /// The state at switch-on: each axis's rate filter starts at the rate `extension`'s
    /// [`SwitchOnRate`] gives for its `switch_on` (as if it had been following that rate), the
    /// auxiliary filters as at [`Self::POWER_ON`].
    pub fn power_on_after(extension: &Extension, switch_on: &[SwitchOn; AXES]) -> Self {
        let mut state = Self::POWER_ON;
        let time_constant_ms = extension.terms.iter().find_map(|t| match t.term {
            Term::TemperatureRate { time_constant_ms } => Some(time_constant_ms),
            _ => None,
        });
        if let Some(time_constant_ms) = time_constant_ms {
            let tau_s = time_constant_ms as f32 / 1000.0;
            for ((filtered, start_rate), switch_on) in state
                .filtered_rise
                .iter_mut()
                .zip(&extension.switch_on_rate)
                .zip(switch_on)
            {
                // The rate estimate is (rise − filtered)/τ and the rise is 0 at switch-on.
                let start = -start_rate.rate(switch_on) * tau_s;
                *filtered = if start.is_finite() { start } else { 0.0 };
            }
        }
        state
    }

    /// Advances the filters to this sample and returns the centred term values: the values the
    /// corrector multiplies by the coefficients, the same bits. A term whose auxiliary input is
    /// not finite holds its last filtered value (0 before the first finite one).
    pub fn values(&mut self, extension: &Extension, inputs: &TermInputs) -> TermValues {
        let previous_ms = self.last_ms;
        let elapsed_ms = self.elapsed_ms(inputs.since_power_on_ms);
        let filtered_rise = &mut self.filtered_rise;
        let mut rates = None;
        let mut values = [[0.0; MAX_TERMS]; AXES];
        for (t, (term, held)) in extension.terms.iter().zip(&mut self.aux).enumerate() {
            let raw = match term.term {
                Term::TemperatureRate { time_constant_ms } => *rates.get_or_insert_with(|| {
                    step_rates(
                        filtered_rise,
                        time_constant_ms,
                        elapsed_ms,
                        &inputs.rise_celsius,
                    )
                }),
                Term::Aux {
                    input,
                    time_constant_ms,
                }
                | Term::AuxTimesRise {
                    input,
                    time_constant_ms,
                } => {
                    let input = shared(&inputs.aux, input);
                    let tau_ms = time_constant_ms.min(previous_ms);
                    aux_value(held, term, input, tau_ms, elapsed_ms, &inputs.rise_celsius).0
                }
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

    /// Advances the filters to this sample and returns the extension's bias per axis, °/s — the
    /// same bits as [`Extension::bias`] of [`Self::values`], without the value matrix — and
    /// whether an auxiliary input a term reads was not finite (that term then holds).
    #[inline(always)]
    pub(crate) fn bias(
        &mut self,
        extension: &Extension,
        since_power_on_ms: u32,
        rise_celsius: &[f32; AXES],
        aux: &[f32; AUX_INPUTS],
    ) -> ([f32; AXES], bool) {
        let previous_ms = self.last_ms;
        let elapsed_ms = self.elapsed_ms(since_power_on_ms);
        let mut rates = None;
        let mut inputs_ok = true;
        let [mut x, mut y, mut z] = [0.0_f32; AXES];
        let filtered_rise = &mut self.filtered_rise;
        for (term, held) in extension.terms.iter().zip(&mut self.aux) {
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
                    add(*rates.get_or_insert_with(|| {
                        step_rates(filtered_rise, time_constant_ms, elapsed_ms, rise_celsius)
                    }))
                }
                // One arm for both auxiliary kinds: a separate arm for the interaction cost the
                // other terms 30 instructions per sample on the Cortex-M4 (614.3 against 584.3).
                Term::Aux {
                    input,
                    time_constant_ms,
                }
                | Term::AuxTimesRise {
                    input,
                    time_constant_ms,
                } => {
                    let tau_ms = time_constant_ms.min(previous_ms);
                    let (value, ok) = aux_value(
                        held,
                        term,
                        shared(aux, input),
                        tau_ms,
                        elapsed_ms,
                        rise_celsius,
                    );
                    inputs_ok &= ok;
                    add(value);
                }
                Term::AxisRise { axis } => add([shared(rise_celsius, axis); AXES]),
                Term::RiseSquared => add(rise_celsius.map(|rise| rise * rise)),
            }
        }
        ([x, y, z], !inputs_ok)
    }

    /// Time since the previous sample, ms; remembers this sample's time.
    #[inline(always)]
    fn elapsed_ms(&mut self, since_power_on_ms: u32) -> u32 {
        let elapsed_ms = since_power_on_ms.saturating_sub(self.last_ms);
        self.last_ms = since_power_on_ms;
        elapsed_ms
    }
}

/// Steps the rate filters of time constant `tau_ms` by `elapsed_ms` to each axis's `rise_celsius`;
/// returns each axis's temperature rate, °C/s.
#[inline(always)]
fn step_rates(
    filtered_rise: &mut [f32; AXES],
    tau_ms: u32,
    elapsed_ms: u32,
    rise_celsius: &[f32; AXES],
) -> [f32; AXES] {
    // Both below 2^24 in practice (τ is seconds, Δt milliseconds to seconds), so exact. Two
    // divisions per sample rather than a cache keyed by (τ, Δt): the cache cost 20 bytes of
    // state and, counted in instructions, more than it saved.
    let (tau, elapsed) = (tau_ms as f32, elapsed_ms as f32);
    let keep = tau / (tau + elapsed);
    let per_second = 1000.0 / tau;
    let mut rates = [0.0; AXES];
    for ((rate, rise), filtered) in rates.iter_mut().zip(rise_celsius).zip(filtered_rise) {
        // Backward Euler of the first-order low-pass r_f' = (r − r_f)/τ, written for the lag
        // d = r − r_f: d = (r − r_f,previous) · τ/(τ + Δt); the rate estimate is d/τ. Stable for
        // any step, no exp(). A rounding of the stored r_f decays with the filter rather than
        // accumulating (|error| ≤ 8e-6 °C/s at 1 kHz over a 5 °C rise, against an f64 filter).
        let lag = (rise - *filtered) * keep;
        *rate = lag * per_second;
        *filtered = rise - lag;
    }
    rates
}

/// One auxiliary term's value for every axis from its filter `held` and this sample's `input`,
/// and whether the input was finite. The filter is the backward Euler step of the first-order
/// low-pass `f' = (u − f)/τ`: `f ← u + (f − u) · τ/(τ + Δt)` (τ = 0: `f ← u`); it starts at the
/// first finite input and holds through non-finite ones. Before any, the value is the term's
/// centre (the term adds 0). [`Term::AuxTimesRise`] multiplies the filtered input by each axis's
/// `rise_celsius`. The callers pass `τ = min(τ_term, t_previous)`, the previous
/// sample's time since switch-on: until `τ_term` has passed, the filter is the time-weighted mean
/// of the inputs so far, so the first reading's noise does not linger for `τ`.
#[inline(always)]
fn aux_value(
    held: &mut f32,
    term: &ExtraTerm,
    input: f32,
    tau_ms: u32,
    elapsed_ms: u32,
    rise_celsius: &[f32; AXES],
) -> ([f32; AXES], bool) {
    let ok = input.is_finite();
    if ok {
        *held = if tau_ms == 0 || held.is_nan() {
            input
        } else {
            let tau = tau_ms as f32;
            input + (*held - input) * (tau / (tau + elapsed_ms as f32))
        };
    }
    let value = *held;
    let values = if value.is_nan() {
        term.centre
    } else if matches!(term.term, Term::AuxTimesRise { .. }) {
        rise_celsius.map(|rise| value * rise)
    } else {
        [value; AXES]
    };
    (values, ok)
}

/// A term that reads the same input for every axis: input `index` of `inputs` (NaN if missing).
#[inline(always)]
fn shared<const N: usize>(inputs: &[f32; N], index: u8) -> f32 {
    inputs.get(usize::from(index)).copied().unwrap_or(f32::NAN)
}
