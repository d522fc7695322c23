//! Fitting, the std/f64 half of gyrodrift's calibration: one activation's recording → its drift and
//! temperature-rise curves → the paper's tables and the polynomial baselines.
//!
//! - [`analyse`] turns one activation into its low-frequency drift and temperature-rise curves;
//! - [`fit`] groups activations into the paper's curves ([`curves`]), picks reference times
//!   ([`knots`]) and builds the paper's tables ([`drift_core::ModifiedTables`]), the same curves
//!   keyed by heating history ([`history_order`]) and the two polynomial baselines;
//! - [`turn_on`] fits the recommended model's turn-on bias ([`drift_core::RecommendedTables`]);
//! - [`regression`] is the one least-squares solver the fitting and the closed loop share.
//!
//! Evaluation lives in `drift-evaluate`, the closed loop in `drift-diagnose`; both build on this
//! crate, never the other way round.

pub mod analyse;
pub mod baselines;
pub mod curves;
pub mod error;
pub mod fit;
pub mod history_order;
pub mod knots;
pub mod lowpass;
mod parallel;
pub mod regression;
pub mod settings;
pub mod turn_on;
mod windows;

pub use error::FitError;
pub use fit::{fit_unit, FittedUnit};
pub use settings::FitSettings;
