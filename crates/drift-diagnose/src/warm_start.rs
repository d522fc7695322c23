//! Whether the loop's model takes the initial bias of warm starts from the calibration
//! (`drift_core::AmbientCurves::warm_starts`) on each axis.
//!
//! The paper reads the initial bias from the switch-on temperature alone. After a short off-time
//! the sensing element is not at the sensor's temperature and is still cooling at switch-on; a bias
//! that depends on the element's temperature or its rate then starts elsewhere, by an amount that
//! depends on the off-time. The calibration's series measure it at each of their off-times, and
//! firmware finds it by the residual heat at switch-on. It is an offset per activation: the drift
//! metric (max − min) cannot see it, the RMS can.

use drift_recording::Segment;
use rayon::prelude::*;
use serde::Serialize;

use crate::keying::Keying;
use crate::statistics::paired_choice;
use drift_evaluate::evaluate::{metric, switch_on_raw};
use drift_fit::fit::FittedUnit;
use drift_fit::settings::FitSettings;

/// The choice on one axis: the warm starts' initial bias where, on the training activations, it
/// leaves a significantly smaller mean square error than the paper's initial bias (paired by
/// activation, one-sided, 5 %), on top of stage 3 as already chosen.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WarmStartChoice {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Training activations compared.
    pub training_activations: usize,
    /// Their RMS error with the paper's initial bias, °/s (root of the mean of the per-activation
    /// mean squares).
    pub training_rms_cold_dps: f64,
    /// The same with the warm starts' initial bias, °/s.
    pub training_rms_warm_dps: f64,
    /// One-sided p-value of "the warm starts' initial bias leaves less error".
    pub p_value: f64,
    /// The choice.
    pub chosen: bool,
}

/// Chooses per axis on the `training` activations, with stage 3 keyed as `keying` says (and what
/// it kept before each activation).
pub fn choose(
    fitted: &FittedUnit,
    keying: &Keying,
    training: &[&Segment],
    settings: &FitSettings,
) -> [WarmStartChoice; 3] {
    let cold = keying.with_warm_start([false; 3]);
    let warm = keying.with_warm_start([true; 3]);
    let (cold_tables, warm_tables) = (
        cold.tables(&fitted.modified, &fitted.by_history),
        warm.tables(&fitted.modified, &fitted.by_history),
    );
    let squares: Vec<([f64; 3], [f64; 3])> = training
        .par_iter()
        .map(|segment| {
            let on = switch_on_raw(segment, settings);
            let window = settings.lowpass_window(segment.sample_rate_hz);
            let (_, rms_cold) = metric(&cold.correct(&cold_tables, segment, on).0, window);
            let (_, rms_warm) = metric(&warm.correct(&warm_tables, segment, on).0, window);
            (rms_cold.map(|r| r * r), rms_warm.map(|r| r * r))
        })
        .collect();
    std::array::from_fn(|a| {
        let choice = paired_choice(&squares, a);
        WarmStartChoice {
            axis: ["X", "Y", "Z"][a],
            training_activations: squares.len(),
            training_rms_cold_dps: choice.current.sqrt(),
            training_rms_warm_dps: choice.alternative.sqrt(),
            p_value: choice.p_value,
            chosen: choice.chosen,
        }
    })
}
