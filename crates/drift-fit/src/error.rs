//! Why a fit or an evaluation could not be made, naming what and where.

use thiserror::Error;

/// A fitting or evaluation error.
#[derive(Debug, Error)]
pub enum FitError {
    /// An activation is too short for the analysis.
    #[error("unit {unit}, set point {set_point} °C, series {series} activation {activation}: {samples} samples is too short (needs {needed})")]
    TooShort {
        /// Unit id.
        unit: String,
        /// Chamber set point, °C.
        set_point: f64,
        /// Series number.
        series: u32,
        /// Activation number.
        activation: u32,
        /// Samples present.
        samples: usize,
        /// Samples needed.
        needed: usize,
    },
    /// An activation's arrays disagree with each other.
    #[error("unit {unit}, series {series} activation {activation}: {what}")]
    Inconsistent {
        /// Unit id.
        unit: String,
        /// Series number.
        series: u32,
        /// Activation number.
        activation: u32,
        /// What disagrees.
        what: String,
    },
    /// The calibration data lacks something the tables need.
    #[error("unit {unit}: {what}")]
    Insufficient {
        /// Unit id.
        unit: String,
        /// What is missing.
        what: String,
    },
    /// The fitted tables failed drift-core's validation (a fitter bug or degenerate data).
    #[error("unit {unit}: fitted {model} table is invalid: {source}")]
    Table {
        /// Unit id.
        unit: String,
        /// Which model.
        model: &'static str,
        /// drift-core's validation error, naming the field.
        source: drift_core::Error,
    },
    /// The caller's [`drift_recording::Progress`] asked the call to stop.
    #[error(transparent)]
    Interrupted(#[from] drift_recording::Interrupted),
    /// Settings out of range.
    #[error("fit setting `{field}`: {problem}")]
    Settings {
        /// The setting.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
}
