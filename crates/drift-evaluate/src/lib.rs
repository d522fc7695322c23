//! Evaluation: fitted tables → drift-core's f32 corrector (exactly what firmware runs) → the residual
//! on activations the fit did not see, and what is measured of it.
//!
//! - [`pipeline`] is the main job's one way through: recording files → segments → fitted tables →
//!   evaluated activations, with the noise floor of a zero-drift twin;
//! - [`evaluate`] corrects one activation and measures the paper's drift metric and the residual
//!   bias; [`summary`] averages the results into the report's records; [`excess`] says how many
//!   times a model cuts the error in excess of the noise floor, with its interval;
//! - [`coverage`] maps the calibration's switch-on temperatures × residual heats and says how much
//!   held-out data fell outside the envelope;
//! - [`check`] answers "is a stored calibration still valid?";
//! - [`noise_floor`] measures a zero-drift twin's floor per group of activations;
//! - [`measured`] says what measured data the paper's method cannot be fitted on still tells;
//! - [`uncertainty`] fits σ(t), the residual bias's standard deviation after switch-on, and
//!   measures how often held-out residuals fall within ±2σ;
//! - [`tables_folder`] writes and reads a fit's tables folder (JSON and firmware images).

pub mod check;
pub mod coverage;
pub mod evaluate;
pub mod excess;
pub mod measured;
pub mod noise_floor;
pub mod pipeline;
pub mod summary;
pub mod tables_folder;
pub mod uncertainty;
