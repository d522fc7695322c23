//! The run-time corrector: immutable model (tables) + small per-unit state, one call per sample.

use crate::error::{Error, Location, Problem};
use crate::extension::{ExtensionState, AUX_INPUTS};
use crate::flags::Flags;
use crate::history::{Previous, SwitchOn};
use crate::model::{AxisModel, ConstDefault, Model};
use crate::settings::Settings;
use crate::AXES;

/// One 3-axis sample as the firmware reads it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Sample {
    /// Time since switch-on, milliseconds (an integer, so hours of operation lose no resolution).
    pub since_power_on_ms: u32,
    /// Measured angular rate per axis, °/s.
    pub rate_dps: [f32; AXES],
    /// Raw temperature-sensor reading per axis, sensor units (see [`Settings`]).
    pub temperature_raw: [f32; AXES],
}

impl Sample {
    /// A sample from integer temperature counts, as a 16-bit sensor reports them;
    /// [`MISSING_TEMPERATURE`](crate::MISSING_TEMPERATURE) on an axis means no reading this sample
    /// (NaN: flagged `TEMPERATURE_INVALID`, the last good drift held). Every other count converts
    /// exactly (`f32` holds every `i16`), so a count gives the same output as its float.
    ///
    /// ```
    /// use drift_core::{Sample, MISSING_TEMPERATURE};
    /// let sample = Sample::from_counts(250, [0.1, -0.2, 0.0], [6123, MISSING_TEMPERATURE, -40]);
    /// assert_eq!(sample.temperature_raw[0], 6123.0);
    /// assert!(sample.temperature_raw[1].is_nan());
    /// ```
    pub const fn from_counts(
        since_power_on_ms: u32,
        rate_dps: [f32; AXES],
        temperature_counts: [i16; AXES],
    ) -> Self {
        let [x, y, z] = temperature_counts;
        Self {
            since_power_on_ms,
            rate_dps,
            temperature_raw: [count(x), count(y), count(z)],
        }
    }
}

const fn count(raw: i16) -> f32 {
    if raw == crate::settings::MISSING_TEMPERATURE {
        f32::NAN
    } else {
        raw as f32
    }
}

/// The corrector's answer for one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Output {
    /// Rate with the estimated zero drift removed, °/s.
    pub corrected_dps: [f32; AXES],
    /// Estimated zero drift that was removed, °/s: initial (switch-on) bias plus the heating drift
    /// since switch-on.
    pub bias_dps: [f32; AXES],
    /// What was clamped, held or passed through, per axis.
    pub flags: [Flags; AXES],
}

/// Run-time state of one axis. Plain data: copy it to persist, restore it to resume.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AxisState<S> {
    switch_on_raw: f32,
    initial_bias_dps: f32,
    /// Initial bias plus the last good drift estimate, held through sensor faults. Kept as the sum,
    /// the bias every sample reports, so a sample adds nothing.
    bias_dps: f32,
    last_raw: f32,
    /// How many samples in a row repeated `last_raw` exactly.
    repeats: u16,
    /// Flags that hold for the whole activation (from switch-on); `NOT_POWERED_ON` while there is
    /// no activation, which makes a separate "powered on" field unnecessary.
    activation_flags: Flags,
    model: S,
}

/// Not powered on: `correct` passes rates through, flagged `NOT_POWERED_ON`.
impl<S: Default> Default for AxisState<S> {
    fn default() -> Self {
        Self {
            switch_on_raw: 0.0,
            initial_bias_dps: 0.0,
            bias_dps: 0.0,
            last_raw: 0.0,
            repeats: 0,
            activation_flags: Flags::NOT_POWERED_ON,
            model: S::default(),
        }
    }
}

/// [`Default`]'s value, for `const` contexts (a unit test checks they agree).
impl<S: ConstDefault> ConstDefault for AxisState<S> {
    const DEFAULT: Self = Self {
        switch_on_raw: 0.0,
        initial_bias_dps: 0.0,
        bias_dps: 0.0,
        last_raw: 0.0,
        repeats: 0,
        activation_flags: Flags::NOT_POWERED_ON,
        model: S::DEFAULT,
    };
}

impl<S> AxisState<S> {
    /// Initial bias located at switch-on, °/s.
    pub fn initial_bias_dps(&self) -> f32 {
        self.initial_bias_dps
    }

    /// Raw temperature reading at switch-on.
    pub fn switch_on_raw(&self) -> f32 {
        self.switch_on_raw
    }

    /// The model's own per-axis state.
    pub fn model(&self) -> &S {
        &self.model
    }
}

/// Per-unit run-time state, separate from the immutable tables: the same tables can serve several
/// units, and swapping tables never corrupts a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CorrectorState<S> {
    axes: [AxisState<S>; AXES],
    extension: ExtensionState,
}

impl<S: ConstDefault> CorrectorState<S> {
    /// A state that has not been powered on: `correct` passes rates through, flagged. A `const fn`,
    /// so a unit's state can be a `static` (an interrupt handler corrects through it with no
    /// `Option` to unwrap; docs/embedded.md):
    ///
    /// ```
    /// use drift_core::{CorrectorState, ModifiedAxisState};
    /// static STATE: CorrectorState<ModifiedAxisState> = CorrectorState::new();
    /// assert!(!STATE.is_powered_on());
    /// ```
    pub const fn new() -> Self {
        Self {
            axes: [
                AxisState::<S>::DEFAULT,
                AxisState::<S>::DEFAULT,
                AxisState::<S>::DEFAULT,
            ],
            extension: ExtensionState::POWER_ON,
        }
    }
}

impl<S: ConstDefault> ConstDefault for CorrectorState<S> {
    const DEFAULT: Self = Self::new();
}

impl<S: Copy + Default> CorrectorState<S> {
    /// The per-axis states, X, Y, Z.
    pub fn axes(&self) -> &[AxisState<S>; AXES] {
        &self.axes
    }

    /// Whether `power_on` has succeeded since the last `power_off`.
    pub fn is_powered_on(&self) -> bool {
        let [x, ..] = &self.axes;
        !x.activation_flags.contains(Flags::NOT_POWERED_ON)
    }

    /// Starts an activation from the raw temperature readings at switch-on, with nothing known of
    /// the previous activation (a table keyed by history then takes a cold start, flagged
    /// `HISTORY_UNKNOWN`; [`Self::power_on_after`] passes what was kept).
    ///
    /// Returns the flags that hold for the whole activation (e.g. an ambient outside the calibrated
    /// range). A non-finite reading is rejected, naming the axis, and the state is left unchanged.
    pub fn power_on<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        self.start(model, switch_on_raw, None, None, &mut [f32::NAN; AXES])
    }

    /// [`Self::power_on`] with the ambient the instrument measured at switch-on (an air or board
    /// thermistor), °C, one for the unit: the paper's stage 2 and initial bias are read there
    /// rather than at each axis's switch-on temperature, which residual heat after a short
    /// off-time and a changing ambient move away from it. Time since switch-on and the rise
    /// (stage 3) are read as always; a table keyed by history reads the residual heat as the
    /// switch-on temperature's height above the ambient ([`SwitchOn::measured`]: a known start).
    /// An ambient outside the calibrated range is flagged `AMBIENT_OUT_OF_RANGE`, as a
    /// switch-on temperature is. Models that read no ambient (the polynomials) start as
    /// [`Self::power_on`] does, with the measured start.
    ///
    /// With the ambient equal to the switch-on temperature on every axis, the activation is the
    /// one [`Self::power_on_after`] starts after [`Previous::COOLED`], bit for bit. A non-finite
    /// `ambient_celsius` or reading is rejected, naming it, and the state is left unchanged.
    ///
    /// Runs once per switch-on: the per-sample path is the same as after [`Self::power_on`].
    pub fn power_on_at_ambient<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
        ambient_celsius: f32,
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        self.start(
            model,
            switch_on_raw,
            None,
            Some(ambient_celsius),
            &mut [f32::NAN; AXES],
        )
    }

    /// [`Self::power_on`] with what firmware kept of the previous activation across power-off
    /// (`previous`, 24 bytes in retained RAM or flash; [`Previous::NOTHING`] at first): a table keyed
    /// by heating history reads the activation's ambient and residual heat from it
    /// ([`SwitchOn::estimate`]); other models ignore it. Writes this activation's ambient into
    /// `previous` and clears its switch-off temperature, which [`Self::keep`] then records.
    pub fn power_on_after<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
        previous: &mut [Previous; AXES],
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        self.start_after(model, switch_on_raw, None, previous)
    }

    /// [`Self::power_on_at_ambient`] with what firmware kept of the previous activation
    /// (`previous`, as for [`Self::power_on_after`]): the measured ambient replaces the estimate,
    /// and what was kept tells how far the cooling had gone ([`SwitchOn::measured`]). Writes the
    /// measured ambient into `previous` and clears its switch-off temperature, which
    /// [`Self::keep`] then records. A non-finite `ambient_celsius` or reading is rejected, naming
    /// it, and neither the state nor `previous` is changed.
    pub fn power_on_after_at_ambient<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
        ambient_celsius: f32,
        previous: &mut [Previous; AXES],
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        self.start_after(model, switch_on_raw, Some(ambient_celsius), previous)
    }

    fn start_after<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
        ambient_celsius: Option<f32>,
        previous: &mut [Previous; AXES],
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let mut ambients = [f32::NAN; AXES];
        let flags = self.start(
            model,
            switch_on_raw,
            Some(previous),
            ambient_celsius,
            &mut ambients,
        )?;
        for (kept, ambient_celsius) in previous.iter_mut().zip(ambients) {
            *kept = Previous {
                ambient_celsius,
                switch_off_celsius: f32::NAN,
            };
        }
        Ok(flags)
    }

    /// Records this activation's last good temperature per axis in `previous` (from
    /// [`Self::power_on_after`]) as its switch-off temperature. Call it before power-off, or
    /// periodically if power can go without warning: an activation whose switch-off temperature
    /// was never recorded leaves the next start unknown (flagged, taken as fully cooled).
    pub fn keep<M>(&self, model: &M, previous: &mut [Previous; AXES])
    where
        M: Model,
    {
        let settings = model.settings();
        for (kept, axis) in previous.iter_mut().zip(&self.axes) {
            if !axis.activation_flags.contains(Flags::NOT_POWERED_ON) {
                kept.switch_off_celsius = settings.celsius(axis.last_raw);
            }
        }
    }

    fn start<M>(
        &mut self,
        model: &M,
        switch_on_raw: [f32; AXES],
        previous: Option<&[Previous; AXES]>,
        measured_ambient: Option<f32>,
        ambients: &mut [f32; AXES],
    ) -> Result<[Flags; AXES], Error>
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        if let Some(axis) = switch_on_raw.iter().position(|raw| !raw.is_finite()) {
            return Err(Error::new(
                "switch_on_raw",
                Location::axis(axis),
                Problem::NonFinite,
            ));
        }
        if measured_ambient.is_some_and(|celsius| !celsius.is_finite()) {
            return Err(Error::new(
                "ambient_celsius",
                Location::default(),
                Problem::NonFinite,
            ));
        }
        let settings = model.settings();
        let mut flags = [Flags::NONE; AXES];
        let mut switch_ons = [SwitchOn::estimate(0.0, None); AXES];
        for (a, ((((state, axis), raw), flags), switch_on)) in self
            .axes
            .iter_mut()
            .zip(model.axes())
            .zip(switch_on_raw)
            .zip(&mut flags)
            .zip(&mut switch_ons)
            .enumerate()
        {
            let celsius = settings.celsius(raw);
            let kept = previous.and_then(|p| p.get(a)).copied();
            *switch_on = match measured_ambient {
                Some(ambient) => SwitchOn::measured(celsius, ambient, kept),
                None => SwitchOn::estimate(celsius, kept),
            };
            if let Some(ambient) = ambients.get_mut(a) {
                *ambient = switch_on.ambient_celsius;
            }
            *state = AxisState {
                switch_on_raw: raw,
                last_raw: raw,
                ..AxisState::default()
            };
            let (initial_bias, mut activation) = if measured_ambient.is_some() {
                axis.power_on_at_ambient(settings, switch_on, &mut state.model)
            } else {
                axis.power_on_after(settings, switch_on, &mut state.model)
            };
            if plausible(initial_bias) {
                state.initial_bias_dps = initial_bias;
            } else {
                activation |= Flags::MODEL_INVALID;
            }
            // The same sum as after a good drift estimate (with no drift yet): the same bits.
            state.bias_dps = state.initial_bias_dps + 0.0;
            state.activation_flags = activation;
            *flags = activation;
        }
        // Without a history every start is taken as cold: the rate filters start at the heating
        // alone.
        self.extension = ExtensionState::power_on_after(model.extension(), &switch_ons);
        Ok(flags)
    }

    /// Ends the activation: further samples pass through, flagged, until the next `power_on`.
    pub fn power_off(&mut self) {
        for axis in &mut self.axes {
            axis.activation_flags |= Flags::NOT_POWERED_ON;
        }
    }

    /// Corrects one sample without auxiliary inputs. Total: never panics, never allocates; every
    /// clamp, hold and fault is in the returned flags. A model whose extra terms read auxiliary
    /// inputs needs [`Self::correct_with_aux`]: here those terms hold, flagged.
    pub fn correct<M>(&mut self, model: &M, sample: &Sample) -> Output
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        self.correct_with_aux(model, sample, &[f32::NAN; AUX_INPUTS])
    }

    /// Corrects `samples` in order into `outputs` without auxiliary inputs and returns how many
    /// (the shorter of the two lengths): the same outputs and the same final state, bit for bit, as
    /// [`Self::correct`] sample by sample. A model with [`AxisModel::drift_of_temperatures`] (the
    /// polynomial baselines) evaluates 128 temperatures at once (~4 KiB of stack);
    /// the checks, holds and flags still run sample by sample.
    pub fn correct_block<M>(
        &mut self,
        model: &M,
        samples: &[Sample],
        outputs: &mut [Output],
    ) -> usize
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let settings = model.settings();
        let answers = self.is_powered_on()
            && model.extension().is_empty()
            && (model.axes().iter().zip(&self.axes)).all(|(axis, state)| {
                axis.drift_of_temperatures(settings, &state.model, &[], &mut [], &mut [])
            });
        let count = samples.len().min(outputs.len());
        if !answers {
            for (sample, output) in samples.iter().zip(outputs.iter_mut()) {
                *output = self.correct(model, sample);
            }
            return count;
        }
        self.correct_blocks_answered(model, samples, outputs);
        count
    }

    /// The block path's loop, out of line so that its ~4 KiB of answers is on the stack only for
    /// a model that answers: the paper's model pays nothing for it in `correct_block`.
    #[inline(never)]
    fn correct_blocks_answered<M>(&mut self, model: &M, samples: &[Sample], outputs: &mut [Output])
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let mut answered = Answers::default();
        let pairs = samples
            .chunks(BLOCK_SAMPLES)
            .zip(outputs.chunks_mut(BLOCK_SAMPLES));
        for (samples, outputs) in pairs {
            if !self.correct_answered(model, samples, outputs, &mut answered) {
                for (sample, output) in samples.iter().zip(outputs.iter_mut()) {
                    *output = self.correct(model, sample);
                }
            }
        }
    }

    /// Up to `BLOCK_SAMPLES` samples of a powered-on activation without extension: the model's
    /// drifts for every temperature first, then the per-sample checks with those answers.
    /// `false`, and nothing changed, if the model does not answer.
    fn correct_answered<M>(
        &mut self,
        model: &M,
        samples: &[Sample],
        outputs: &mut [Output],
        answered: &mut Answers,
    ) -> bool
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let settings = model.settings();
        let celsius_per_raw = settings.celsius_per_raw();
        let count = samples.len();
        let [celsius_x, celsius_y, celsius_z] = &mut answered.celsius;
        let celsius = celsius_x
            .iter_mut()
            .zip(celsius_y.iter_mut().zip(celsius_z.iter_mut()));
        for (sample, (x, (y, z))) in samples.iter().zip(celsius) {
            // A healthy reading is the last good one, which the per-sample path converts: the same
            // bits. The answers for the other readings are never read.
            let [raw_x, raw_y, raw_z] = sample.temperature_raw;
            *x = settings.celsius_with(raw_x, celsius_per_raw);
            *y = settings.celsius_with(raw_y, celsius_per_raw);
            *z = settings.celsius_with(raw_z, celsius_per_raw);
        }
        let lanes = answered
            .celsius
            .iter()
            .zip(&mut answered.drift)
            .zip(&mut answered.flags);
        for ((axis, state), ((celsius, drift), flags)) in
            model.axes().iter().zip(&self.axes).zip(lanes)
        {
            let celsius = celsius.get(..count).unwrap_or_default();
            let drift = drift.get_mut(..count).unwrap_or_default();
            let flags = flags.get_mut(..count).unwrap_or_default();
            if !axis.drift_of_temperatures(settings, &state.model, celsius, drift, flags) {
                return false;
            }
        }
        let [state_x, state_y, state_z] = &mut self.axes;
        let [drift_x, drift_y, drift_z] = &answered.drift;
        let [flags_x, flags_y, flags_z] = &answered.flags;
        let x = drift_x.iter().zip(flags_x);
        let y = drift_y.iter().zip(flags_y);
        let z = drift_z.iter().zip(flags_z);
        let answers = x.zip(y.zip(z));
        for ((sample, output), (x, (y, z))) in samples.iter().zip(outputs.iter_mut()).zip(answers) {
            let [rate_x, rate_y, rate_z] = sample.rate_dps;
            let [raw_x, raw_y, raw_z] = sample.temperature_raw;
            let x = answered_axis(settings, celsius_per_raw, state_x, rate_x, raw_x, x);
            let y = answered_axis(settings, celsius_per_raw, state_y, rate_y, raw_y, y);
            let z = answered_axis(settings, celsius_per_raw, state_z, rate_z, raw_z, z);
            *output = Output {
                corrected_dps: [x.corrected_dps, y.corrected_dps, z.corrected_dps],
                bias_dps: [x.bias_dps, y.bias_dps, z.bias_dps],
                flags: [x.flags, y.flags, z.flags],
            };
        }
        true
    }

    /// Corrects one sample, with the auxiliary inputs the extended model's extra terms may read
    /// (e.g. supply voltage, accelerometer axes, in the order the fit named them).
    pub fn correct_with_aux<M>(
        &mut self,
        model: &M,
        sample: &Sample,
        aux: &[f32; AUX_INPUTS],
    ) -> Output
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        if !self.is_powered_on() {
            return not_powered_on(sample);
        }
        let settings = model.settings();
        let celsius_per_raw = settings.celsius_per_raw();
        // The three axes written out rather than a loop over zipped lanes: the loop kept its seven
        // lane pointers on the stack and reloaded them every axis (~25 instructions per axis).
        let [state_x, state_y, state_z] = &mut self.axes;
        let [axis_x, axis_y, axis_z] = model.axes();
        let [rate_x, rate_y, rate_z] = sample.rate_dps;
        let [raw_x, raw_y, raw_z] = sample.temperature_raw;
        let ms = sample.since_power_on_ms;
        let x = correct_axis(
            axis_x,
            settings,
            celsius_per_raw,
            state_x,
            ms,
            rate_x,
            raw_x,
        );
        let y = correct_axis(
            axis_y,
            settings,
            celsius_per_raw,
            state_y,
            ms,
            rate_y,
            raw_y,
        );
        let z = correct_axis(
            axis_z,
            settings,
            celsius_per_raw,
            state_z,
            ms,
            rate_z,
            raw_z,
        );
        let mut output = Output {
            corrected_dps: [x.corrected_dps, y.corrected_dps, z.corrected_dps],
            bias_dps: [x.bias_dps, y.bias_dps, z.bias_dps],
            flags: [x.flags, y.flags, z.flags],
        };
        let extension = model.extension();
        if !extension.is_empty() {
            // The extra terms read the last good temperature of every axis (a faulty reading is
            // held there, like the paper's drift); an auxiliary term whose input is missing holds
            // its filter.
            let (extra, input_missing) = self.extension.bias(
                extension,
                ms,
                &[x.rise_celsius, y.rise_celsius, z.rise_celsius],
                aux,
            );
            // Written out per axis: a loop over the array's values kept its iterator on the
            // stack (~90 instructions per sample on the Cortex-M4).
            let [extra_x, extra_y, extra_z] = extra;
            let Output {
                corrected_dps: [corrected_x, corrected_y, corrected_z],
                bias_dps: [bias_x, bias_y, bias_z],
                flags: [flags_x, flags_y, flags_z],
            } = &mut output;
            add_extension(extra_x, input_missing, corrected_x, bias_x, flags_x);
            add_extension(extra_y, input_missing, corrected_y, bias_y, flags_y);
            add_extension(extra_z, input_missing, corrected_z, bias_z, flags_z);
        }
        output
    }
}

/// Adds one axis's extension bias `extra` to its output; `input_missing`: an auxiliary input a
/// term reads was not finite (the term held its filter).
#[inline(always)]
fn add_extension(
    extra: f32,
    input_missing: bool,
    corrected: &mut f32,
    bias: &mut f32,
    flags: &mut Flags,
) {
    if input_missing {
        *flags |= Flags::EXTENSION_INPUT_INVALID;
    }
    // Every input the terms read is held finite, so only absurd tables or an absurd (finite)
    // auxiliary reading make the sum implausible: the extension then adds nothing, flagged
    // (finding F3: the corrected rate stays finite).
    let extra = if plausible(extra) {
        extra
    } else {
        *flags |= Flags::EXTENSION_INPUT_INVALID;
        0.0
    };
    *corrected -= extra;
    *bias += extra;
}

/// Before `power_on`: the rates pass through, flagged. Kept out of line: firmware calls it only
/// by mistake.
#[cold]
#[inline(never)]
fn not_powered_on(sample: &Sample) -> Output {
    let mut output = Output {
        corrected_dps: sample.rate_dps,
        ..Output::default()
    };
    for (flags, rate) in output.flags.iter_mut().zip(sample.rate_dps) {
        *flags = Flags::NOT_POWERED_ON | rate_flag(rate);
    }
    output
}

/// The largest drift, initial bias or extra-term contribution (°/s) the corrector believes; a
/// larger one (an extreme but finite temperature or auxiliary reading, corrupt tables) is treated
/// like a non-finite one: flagged, and the last good drift held (the extension adds nothing). No
/// gyro's range comes near it, and
/// it keeps `rate − bias` finite for every finite rate: the spacing of f32 near `f32::MAX` is
/// 2·10³¹, so a bias of a few 10⁴ °/s cannot carry a rate over it (finding F3,
/// docs/reliability.md).
pub const MAX_PLAUSIBLE_DRIFT_DPS: f32 = 1.0e4;

/// Finite and within [`MAX_PLAUSIBLE_DRIFT_DPS`] (NaN compares false). One compare more than
/// `is_finite` would cost: 3–4 instructions per 3-axis sample on the Cortex-M4 (docs/embedded.md).
#[inline(always)]
pub(crate) fn plausible(dps: f32) -> bool {
    dps.abs() <= MAX_PLAUSIBLE_DRIFT_DPS
}

#[inline(always)]
fn rate_flag(rate: f32) -> Flags {
    if rate.is_finite() {
        Flags::NONE
    } else {
        Flags::RATE_INVALID
    }
}

/// One axis of one sample after the shared part: the output, and the last good temperature's rise,
/// which the extended model's terms read.
struct AxisOutput {
    corrected_dps: f32,
    bias_dps: f32,
    flags: Flags,
    rise_celsius: f32,
}

/// One axis of one sample through `axis`: the shared checks, the model where the reading allows,
/// the hold.
#[inline(always)]
fn correct_axis<A: AxisModel>(
    axis: &A,
    settings: &Settings,
    celsius_per_raw: f32,
    state: &mut AxisState<A::State>,
    since_power_on_ms: u32,
    rate: f32,
    raw: f32,
) -> AxisOutput {
    let mut reading = read_axis(settings, celsius_per_raw, state, rate, raw);
    let bias_dps = if reading.healthy {
        let (drift, model_flags) = axis.drift(
            settings,
            &mut state.model,
            since_power_on_ms,
            reading.celsius,
            reading.rise_celsius,
        );
        hold_drift(state, &mut reading, drift, model_flags)
    } else {
        state.bias_dps
    };
    output_of(&reading, rate, bias_dps)
}

/// [`correct_axis`] with the model's answer for this sample's temperature already known.
#[inline(always)]
fn answered_axis<S>(
    settings: &Settings,
    celsius_per_raw: f32,
    state: &mut AxisState<S>,
    rate: f32,
    raw: f32,
    (&drift, &model_flags): (&f32, &Flags),
) -> AxisOutput {
    let mut reading = read_axis(settings, celsius_per_raw, state, rate, raw);
    let bias_dps = if reading.healthy {
        hold_drift(state, &mut reading, drift, model_flags)
    } else {
        state.bias_dps
    };
    output_of(&reading, rate, bias_dps)
}

/// One axis's output from its checked reading and the bias held for it.
#[inline(always)]
fn output_of(reading: &Reading, rate: f32, bias_dps: f32) -> AxisOutput {
    AxisOutput {
        corrected_dps: rate - bias_dps,
        bias_dps,
        flags: reading.flags,
        rise_celsius: reading.rise_celsius,
    }
}

/// Samples the block path evaluates at once: a multiple of the polynomial's lanes, few enough for
/// the stack.
const BLOCK_SAMPLES: usize = 128;

/// The block path's per-axis temperatures and the model's answers for them. Reused from block to
/// block; entries past a short block are neither evaluated nor read.
struct Answers {
    celsius: [[f32; BLOCK_SAMPLES]; AXES],
    drift: [[f32; BLOCK_SAMPLES]; AXES],
    flags: [[Flags; BLOCK_SAMPLES]; AXES],
}

impl Default for Answers {
    fn default() -> Self {
        Self {
            celsius: [[0.0; BLOCK_SAMPLES]; AXES],
            drift: [[0.0; BLOCK_SAMPLES]; AXES],
            flags: [[Flags::NONE; BLOCK_SAMPLES]; AXES],
        }
    }
}

/// What the shared checks found for one axis's reading.
struct Reading {
    flags: Flags,
    /// Valid and not stuck: the model is asked, at `celsius` and `rise_celsius`.
    healthy: bool,
    /// The last good reading in °C: this sample's when it is valid (the same bits), else the held
    /// one, which the extension reads.
    celsius: f32,
    /// Its rise since switch-on, °C.
    rise_celsius: f32,
}

/// The checks every model shares, before the model: activation, rate and temperature faults, the
/// stuck counter.
#[inline(always)]
fn read_axis<S>(
    settings: &Settings,
    celsius_per_raw: f32,
    state: &mut AxisState<S>,
    rate: f32,
    raw: f32,
) -> Reading {
    let mut flags = state.activation_flags | rate_flag(rate);
    let valid = raw.is_finite();
    let mut stuck = false;
    if valid {
        if raw.to_bits() == state.last_raw.to_bits() {
            state.repeats = state.repeats.saturating_add(1);
            stuck =
                settings.stuck_after_samples != 0 && state.repeats >= settings.stuck_after_samples;
        } else {
            state.repeats = 0;
            state.last_raw = raw;
        }
    }
    if !valid {
        flags |= Flags::TEMPERATURE_INVALID;
    } else if stuck {
        flags |= Flags::TEMPERATURE_STUCK;
    }
    Reading {
        flags,
        healthy: valid && !stuck,
        celsius: settings.celsius_with(state.last_raw, celsius_per_raw),
        rise_celsius: (state.last_raw - state.switch_on_raw) * celsius_per_raw,
    }
}

/// The model's answer for a healthy reading: its flags, and its drift held unless non-finite.
/// Returns the held bias, so the output does not read back what was just stored.
#[inline(always)]
fn hold_drift<S>(
    state: &mut AxisState<S>,
    reading: &mut Reading,
    drift: f32,
    model_flags: Flags,
) -> f32 {
    reading.flags |= model_flags;
    if plausible(drift) {
        let bias_dps = state.initial_bias_dps + drift;
        state.bias_dps = bias_dps;
        bias_dps
    } else {
        reading.flags |= Flags::MODEL_INVALID;
        state.bias_dps
    }
}

/// A model together with one unit's state: the convenient way to run a corrector.
///
/// ```
/// use drift_core::{Corrector, PolynomialAxis, PolynomialTables, Sample, Settings};
/// let axis = PolynomialAxis {
///     range_celsius: [20.0, 40.0],
///     coefficients: heapless::Vec::from_slice(&[0.5, 0.01]).unwrap(),
/// };
/// let model = PolynomialTables::try_new(Settings::default(), [axis.clone(), axis.clone(), axis])?;
/// let mut corrector = Corrector::new(&model)?;
/// corrector.power_on([6000.0; 3])?; // 30 °C at 200 raw units per °C
/// let out = corrector.correct(&Sample {
///     since_power_on_ms: 1,
///     rate_dps: [0.5; 3],
///     temperature_raw: [6000.0; 3],
/// });
/// assert!(out.corrected_dps[0].abs() < 1e-6);
/// # Ok::<(), drift_core::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Corrector<'a, M: Model> {
    model: &'a M,
    state: CorrectorState<<M::Axis as AxisModel>::State>,
}

impl<'a, M: Model> Corrector<'a, M> {
    /// Validates the model once, so that the per-sample path works on checked tables.
    pub fn new(model: &'a M) -> Result<Self, Error> {
        model.validate()?;
        Ok(Self {
            model,
            state: CorrectorState::default(),
        })
    }

    /// The model in use.
    pub fn model(&self) -> &'a M {
        self.model
    }

    /// The unit's run-time state.
    pub fn state(&self) -> &CorrectorState<<M::Axis as AxisModel>::State> {
        &self.state
    }

    /// See [`CorrectorState::power_on`].
    pub fn power_on(&mut self, switch_on_raw: [f32; AXES]) -> Result<[Flags; AXES], Error> {
        self.state.power_on(self.model, switch_on_raw)
    }

    /// See [`CorrectorState::power_on_after`].
    pub fn power_on_after(
        &mut self,
        switch_on_raw: [f32; AXES],
        previous: &mut [Previous; AXES],
    ) -> Result<[Flags; AXES], Error> {
        self.state
            .power_on_after(self.model, switch_on_raw, previous)
    }

    /// See [`CorrectorState::power_on_at_ambient`].
    pub fn power_on_at_ambient(
        &mut self,
        switch_on_raw: [f32; AXES],
        ambient_celsius: f32,
    ) -> Result<[Flags; AXES], Error> {
        self.state
            .power_on_at_ambient(self.model, switch_on_raw, ambient_celsius)
    }

    /// See [`CorrectorState::power_on_after_at_ambient`].
    pub fn power_on_after_at_ambient(
        &mut self,
        switch_on_raw: [f32; AXES],
        ambient_celsius: f32,
        previous: &mut [Previous; AXES],
    ) -> Result<[Flags; AXES], Error> {
        self.state
            .power_on_after_at_ambient(self.model, switch_on_raw, ambient_celsius, previous)
    }

    /// See [`CorrectorState::keep`].
    pub fn keep(&self, previous: &mut [Previous; AXES]) {
        self.state.keep(self.model, previous);
    }

    /// See [`CorrectorState::power_off`].
    pub fn power_off(&mut self) {
        self.state.power_off();
    }

    /// See [`CorrectorState::correct`].
    pub fn correct(&mut self, sample: &Sample) -> Output {
        self.state.correct(self.model, sample)
    }

    /// See [`CorrectorState::correct_with_aux`].
    pub fn correct_with_aux(&mut self, sample: &Sample, aux: &[f32; AUX_INPUTS]) -> Output {
        self.state.correct_with_aux(self.model, sample, aux)
    }

    /// See [`CorrectorState::correct_block`].
    pub fn correct_block(&mut self, samples: &[Sample], outputs: &mut [Output]) -> usize {
        self.state.correct_block(self.model, samples, outputs)
    }
}

#[cfg(test)]
mod tests {
    use super::CorrectorState;
    use crate::ModifiedAxisState;

    /// The floor for a unit's run-time state, 256 bytes, extension included (docs/embedded.md). The
    /// layout has no pointers, so the host's size is the Cortex-M4's (which the firmware prints).
    #[test]
    fn the_constant_state_is_the_default() {
        use crate::{ConstDefault, PolynomialAxisState};
        assert_eq!(
            CorrectorState::<ModifiedAxisState>::new(),
            CorrectorState::default()
        );
        assert_eq!(
            CorrectorState::<PolynomialAxisState>::new(),
            CorrectorState::default()
        );
        assert_eq!(ModifiedAxisState::DEFAULT, ModifiedAxisState::default());
    }

    #[test]
    fn state_fits_its_floor() {
        assert!(core::mem::size_of::<CorrectorState<ModifiedAxisState>>() <= 256);
    }
}
