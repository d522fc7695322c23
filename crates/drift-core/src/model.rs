//! The interface every drift model implements, so the paper's method and its baselines are run,
//! flagged and compared the same way, in firmware and in analysis.

use crate::error::Error;
use crate::extension::Extension;
use crate::flags::Flags;
use crate::history::SwitchOn;
use crate::settings::Settings;
use crate::AXES;

/// [`Default`] as a constant, so that a unit's run-time state can be built in a `const` context
/// ([`crate::CorrectorState::new`] is a `const fn`): firmware declares it as a `static`, with no
/// `Option` or `RefCell` to fill at start-up.
pub trait ConstDefault: Sized {
    /// The value [`Default::default`] returns.
    const DEFAULT: Self;
}

/// One axis of a drift model: what it needs at switch-on and per sample.
///
/// Implementations are pure functions of their (immutable) calibration data and the small per-axis
/// `State`; the [`Corrector`](crate::Corrector) adds the shared parts (raw-to-°C conversion, rise,
/// sensor-fault holds, flags).
pub trait AxisModel {
    /// Per-axis run-time state the model keeps between switch-on and each sample.
    type State: Copy + Default + ConstDefault + core::fmt::Debug;

    /// Prepares `state` at switch-on from the switch-on temperature (°C); returns the initial bias
    /// (°/s) and any envelope flags that hold for the whole activation.
    fn power_on(
        &self,
        settings: &Settings,
        switch_on_celsius: f32,
        state: &mut Self::State,
    ) -> (f32, Flags);

    /// [`Self::power_on`] with what firmware knows of the heating history (ambient and residual
    /// heat at switch-on). Models that do not key anything by history (the default) ignore it.
    fn power_on_after(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        self.power_on(settings, switch_on.switch_on_celsius, state)
    }

    /// [`Self::power_on_after`] with an ambient the instrument measured at switch-on
    /// (`switch_on` from [`SwitchOn::measured`]): a model that reads anything at the ambient (the
    /// paper's stage 2 and initial bias) reads it at `switch_on.ambient_celsius`, not at the
    /// switch-on temperature. Models that read no ambient (the default) take it as
    /// [`Self::power_on_after`] does.
    fn power_on_at_ambient(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        self.power_on_after(settings, switch_on, state)
    }

    /// The drift since switch-on (°/s, excluding the initial bias) at `since_power_on_ms`, for the
    /// current temperature (°C) and its rise since switch-on (°C), with envelope flags.
    /// May return a non-finite value only for corrupt tables; the corrector then holds and flags.
    fn drift(
        &self,
        settings: &Settings,
        state: &mut Self::State,
        since_power_on_ms: u32,
        temperature_celsius: f32,
        rise_celsius: f32,
    ) -> (f32, Flags);

    /// [`Self::drift`] for many temperatures at once, for a model whose drift depends on the
    /// temperature alone (not on time, rise or a state that changes per sample): writes what
    /// `drift` returns for each of `celsius` (°C) into `drift` and `model_flags` (the same
    /// lengths), the same bits, and returns `true`. The corrector's block path asks before its
    /// per-sample checks, so that the model's arithmetic runs in loops the compiler vectorises
    /// (the polynomial baselines). The default writes nothing and returns `false`: the corrector
    /// goes sample by sample. A model answers for every length (none included) or for none.
    fn drift_of_temperatures(
        &self,
        _settings: &Settings,
        _state: &Self::State,
        _celsius: &[f32],
        _drift: &mut [f32],
        _model_flags: &mut [Flags],
    ) -> bool {
        false
    }
}

/// A drift model for a whole unit: settings plus one [`AxisModel`] per axis.
pub trait Model {
    /// The per-axis model.
    type Axis: AxisModel;

    /// Sensor conversion and envelope settings.
    fn settings(&self) -> &Settings;

    /// The per-axis models, X, Y, Z.
    fn axes(&self) -> &[Self::Axis; AXES];

    /// Checks every value; the error names the field and where it sits.
    fn validate(&self) -> Result<(), Error>;

    /// Extra linear terms on top of the per-axis model (none unless the model carries them).
    fn extension(&self) -> &Extension {
        &NO_EXTENSION
    }
}

static NO_EXTENSION: Extension = Extension::NONE;
