//! Fitting and evaluation, the std/f64 half of gyrodrift: segments → fitted tables → corrector →
//! residual.
//!
//! - [`analyse`] turns one activation into its low-frequency drift and temperature-rise curves;
//! - [`fit`] groups activations into the paper's curves, picks reference times, and builds the
//!   paper's tables ([`drift_core::ModifiedTables`]) and the two polynomial baselines;
//! - [`evaluate`] runs the fitted models through drift-core's f32 corrector (exactly what firmware
//!   runs) on activations the fit did not see, and measures the paper's drift metric.

pub mod absorb;
pub mod analyse;
pub mod baselines;
pub mod candidates;
pub mod check;
pub mod closing;
pub mod curves;
pub mod diagnose;
pub mod error;
pub mod evaluate;
pub mod excess;
pub mod extend;
pub mod fit;
pub mod history_order;
pub mod keying;
pub mod knots;
pub mod lowpass;
pub mod measured;
pub mod parallel;
pub mod pipeline;
pub mod roles;
pub mod settings;
pub mod summary;
pub mod switch_on_rate;
pub mod warm_start;
pub mod windows;

pub use error::FitError;
pub use fit::{fit_unit, FittedUnit};
pub use settings::FitSettings;
