#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic,
        clippy::float_cmp,
        clippy::arithmetic_side_effects
    )
)]

#[cfg(test)]
extern crate std;

#[cfg(feature = "serde")]
pub mod blob;
mod corrector;
mod envelope;
mod error;
mod extension;
mod flags;
mod history;
mod interp;
mod model;
mod modified;
mod polynomial;
mod recommended;
mod settings;
mod stage;
mod stillness;
mod table;
mod uncertainty;
mod warm_start;

pub use corrector::{
    AxisState, Corrector, CorrectorState, Output, Sample, MAX_PLAUSIBLE_DRIFT_DPS,
};
pub use envelope::Envelope;
pub use error::{Error, Location, Problem};
pub use extension::{
    Extension, ExtensionState, ExtraTerm, SwitchOnRate, Term, TermInputs, TermValues, AUX_INPUTS,
    MAX_TERMS,
};
pub use flags::Flags;
pub use history::{Previous, SwitchOn};
pub use model::{AxisModel, ConstDefault, Model};
pub use modified::ModifiedAxisState;
pub use polynomial::{
    PolynomialAxis, PolynomialAxisState, PolynomialTables, RelativePolynomialAxis,
    RelativePolynomialTables, MAX_POLYNOMIAL_COEFFICIENTS,
};
pub use recommended::{RecommendedAxis, RecommendedTables, TurnOn};
pub use settings::{SensorSettings, Settings, MISSING_TEMPERATURE};
pub use stage::ambient::AmbientPosition;
pub use stage::since_power_on::{Moment, Segment, SegmentKind};
pub use stillness::{StillnessLearner, StillnessOutput, StillnessSettings};
pub use table::{
    AmbientCurves, AxisTable, Curve, CurvePoint, ModifiedTables, MAX_PLAUSIBLE_K,
    MAX_PLAUSIBLE_RISE_CELSIUS, MAX_PLAUSIBLE_STORED_DRIFT_DPS,
};
pub use uncertainty::{ActivationClass, SigmaState, Uncertainty, ACTIVATION_CLASSES, SIGMA_KNOTS};
pub use warm_start::WarmStart;

/// Number of gyro axes in a unit (X, Y, Z). Each axis has its own temperature sensor.
pub const AXES: usize = 3;
