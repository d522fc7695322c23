//! σ(t), the residual bias's standard deviation after switch-on, fitted and checked.
//!
//! Fitted on the calibration activations, each corrected by tables fitted without its repeat (the
//! pipeline's leave-one-repeat-out refits), so σ measures what tables leave on activations they did
//! not see; checked on the validation and field activations, which neither the tables nor σ saw.
//! The residual is the corrected rate's 1-s centred moving average (the unit is static: the true
//! rate is zero), taken every [`EVERY_MS`]. Per class and knot, σ is half the 95th percentile of
//! |residual| over every axis (so ±2σ holds 95 % of the calibration's residuals whatever their
//! distribution); between knots it is linear (drift-core's [`Uncertainty::sigma_dps`]).

pub use drift_core::ActivationClass;
use drift_core::{
    Model, Previous, SigmaState, SwitchOn, TurnOn, Uncertainty, ACTIVATION_CLASSES, SIGMA_KNOTS,
};
use drift_fit::lowpass::centred_moving_average;
use drift_fit::settings::FitSettings;
use drift_fit::FittedUnit;
use drift_recording::Segment;
use serde::Serialize;

use crate::evaluate::{correct_segment_after, sample_at, switch_on_raw};
use crate::summary::Split;

/// The knots of σ(t), ms since switch-on: dense where the switch-on transient is.
pub const KNOTS_MS: [u32; SIGMA_KNOTS] = [0, 2_000, 5_000, 10_000, 20_000, 40_000, 80_000, 160_000];

/// Residual heat at switch-on above which an activation is a warm restart, °C: above the
/// temperature sensors' noise in the switch-on mean, below the heat a unit keeps after the shortest
/// off-times of a calibration protocol.
pub const WARM_ABOVE_CELSIUS: f32 = 0.5;

/// How often the residual is kept, ms: the 1-s average changes little within it.
pub const EVERY_MS: u32 = 100;

/// The share of residuals ±2σ is fitted to hold.
pub const TARGET: f64 = 0.95;

/// One activation's residual, as σ(t) is fitted and checked on.
#[derive(Debug, Clone)]
pub struct Residuals {
    /// The unit.
    pub unit_id: String,
    /// The activation's nominal set point, °C.
    pub set_point_celsius: f64,
    /// Per axis, what firmware estimates at switch-on ([`SwitchOn::estimate`]).
    pub switch_on: [SwitchOn; 3],
    /// Per axis, the mean uncorrected rate over the activation, °/s.
    pub mean_uncorrected_dps: [f64; 3],
    /// Every [`EVERY_MS`]: ms since switch-on and the 1-s residual per axis, °/s.
    pub samples: Vec<(u32, [f32; 3])>,
}

/// Corrects `segment` with `model` started after `previous` (what firmware kept) and keeps its
/// 1-s residual every [`EVERY_MS`].
pub fn residuals<M: Model>(
    model: &M,
    segment: &Segment,
    settings: &FitSettings,
    previous: &[Previous; 3],
) -> Residuals {
    let raw = switch_on_raw(segment, settings);
    let core = model.settings();
    let switch_on =
        std::array::from_fn(|a| SwitchOn::estimate(core.celsius(raw[a]), Some(previous[a])));
    let (corrected, _) = correct_segment_after(model, segment, raw, Some(previous));
    let window = settings.lowpass_window(segment.sample_rate_hz);
    let low: [Vec<f64>; 3] = std::array::from_fn(|a| centred_moving_average(&corrected[a], window));
    let mean_uncorrected_dps = std::array::from_fn(|a| {
        let rate = &segment.rate_dps[a];
        rate.iter().map(|&v| f64::from(v)).sum::<f64>() / rate.len().max(1) as f64
    });
    let mut samples = Vec::new();
    let mut next_ms = 0;
    for i in 0..segment.len() {
        let ms = sample_at(segment, i).since_power_on_ms;
        if ms < next_ms {
            continue;
        }
        next_ms = ms.saturating_add(EVERY_MS);
        let r = [0, 1, 2].map(|a| low[a].get(i).copied().unwrap_or(f64::NAN) as f32);
        if r.iter().all(|v| v.is_finite()) {
            samples.push((ms, r));
        }
    }
    Residuals {
        unit_id: segment.labels.unit_id.clone(),
        set_point_celsius: segment.labels.nominal_set_point_celsius(),
        switch_on,
        mean_uncorrected_dps,
        samples,
    }
}

/// σ(t) without its curves: the calibrated envelope, the class threshold and the growth outside.
/// The ambient envelope is the calibration's set points; the growth per °C outside it is how far
/// the mean uncorrected rate moves per °C of ambient between the lowest and the highest of them
/// (the largest over axes): the error a table clamped at its envelope's edge makes per °C beyond
/// it. The residual heat's envelope is the tables' (`turn_on`, per axis: the most residual heat
/// the turn-on bias was fitted on, beyond which the corrector holds it); the growth per °C beyond
/// it is the fitted turn-on bias's slope in residual heat (the largest over axes): the error of a
/// turn-on bias held at the most heat per °C beyond it.
pub fn envelope(calibration: &[Residuals], turn_on: &[TurnOn; 3]) -> Uncertainty {
    let lo = calibration
        .iter()
        .map(|r| r.set_point_celsius)
        .fold(f64::INFINITY, f64::min);
    let hi = calibration
        .iter()
        .map(|r| r.set_point_celsius)
        .fold(f64::NEG_INFINITY, f64::max);
    let mean_at = |set_point: f64, axis: usize| {
        let at: Vec<f64> = calibration
            .iter()
            .filter(|r| (r.set_point_celsius - set_point).abs() < 1e-6)
            .map(|r| r.mean_uncorrected_dps[axis])
            .collect();
        at.iter().sum::<f64>() / at.len().max(1) as f64
    };
    let per_celsius = if hi > lo {
        (0..3)
            .map(|a| ((mean_at(hi, a) - mean_at(lo, a)) / (hi - lo)).abs())
            .fold(0.0, f64::max)
    } else {
        0.0
    };
    let finite = |v: f64| if v.is_finite() { v as f32 } else { 0.0 };
    Uncertainty {
        knots_ms: KNOTS_MS,
        sigma_dps: [[0.0; SIGMA_KNOTS]; ACTIVATION_CLASSES],
        warm_above_celsius: WARM_ABOVE_CELSIUS,
        ambient_min_celsius: finite(lo),
        ambient_max_celsius: finite(hi.max(lo)),
        per_celsius_outside_dps: finite(per_celsius),
        most_residual_heat_celsius: turn_on
            .each_ref()
            .map(|t| finite(f64::from(t.most_residual_heat_celsius)).max(0.0)),
        per_residual_celsius_beyond_dps: turn_on
            .iter()
            .map(|t| finite(f64::from(t.dps_per_residual_celsius)).abs())
            .fold(0.0, f32::max),
    }
}

/// The knot a time belongs to: the nearest one.
fn knot_of(ms: u32) -> usize {
    let mut best = 0;
    for (k, &knot) in KNOTS_MS.iter().enumerate() {
        if ms.abs_diff(knot) < ms.abs_diff(KNOTS_MS[best]) {
            best = k;
        }
    }
    best
}

/// The `q` quantile of `values` (sorted in place; linear between order statistics); None if empty.
fn quantile(values: &mut [f32], q: f64) -> Option<f32> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f32::total_cmp);
    let at = q * (values.len() - 1) as f64;
    let (i, frac) = (at.floor() as usize, at - at.floor());
    let low = f64::from(values[i]);
    let high = f64::from(values[(i + 1).min(values.len() - 1)]);
    Some((low + (high - low) * frac) as f32)
}

/// σ(t) fitted on `calibration` (one unit's residuals on activations the tables did not see), for
/// tables whose turn-on bias is `turn_on`. A class or knot without residuals takes the pooled
/// classes' value at that knot, then the previous knot's.
pub fn fit(calibration: &[Residuals], turn_on: &[TurnOn; 3]) -> Uncertainty {
    let mut u = envelope(calibration, turn_on);
    u.sigma_dps = curves(&u, calibration, false);
    u
}

/// The curves of σ(t) fitted on `residuals` within the envelope and widening of `u` (its curves
/// unused): per class and knot, half the [`TARGET`] quantile of |residual| over every axis. With
/// `inside_only`, activation × axis pairs outside the envelope (where σ widens) are left out.
fn curves(
    u: &Uncertainty,
    residuals: &[Residuals],
    inside_only: bool,
) -> [[f32; SIGMA_KNOTS]; ACTIVATION_CLASSES] {
    let mut by = vec![vec![Vec::new(); SIGMA_KNOTS]; ACTIVATION_CLASSES + 1];
    for r in residuals {
        let state = u.start(&r.switch_on);
        for &(ms, residual) in &r.samples {
            let k = knot_of(ms);
            for ((class, value), widening) in
                state.class.iter().zip(residual).zip(state.widening_dps)
            {
                if inside_only && widening > 0.0 {
                    continue;
                }
                by[*class as usize][k].push(value.abs());
                by[ACTIVATION_CLASSES][k].push(value.abs());
            }
        }
    }
    let mut pooled = [0.0f32; SIGMA_KNOTS];
    let mut previous = 0.0;
    for (k, value) in pooled.iter_mut().enumerate() {
        *value = quantile(&mut by[ACTIVATION_CLASSES][k], TARGET).map_or(previous, |q| q / 2.0);
        previous = *value;
    }
    let mut out = [[0.0; SIGMA_KNOTS]; ACTIVATION_CLASSES];
    for (c, row) in out.iter_mut().enumerate() {
        for (k, sigma) in row.iter_mut().enumerate() {
            *sigma = quantile(&mut by[c][k], TARGET).map_or(pooled[k], |q| q / 2.0);
        }
    }
    out
}

/// σ(t) with the envelope and widening of `u` and its curves fitted on `residuals` inside the
/// envelope: what the calibration would have had to give for these residuals.
fn refitted_on(u: &Uncertainty, residuals: &[Residuals]) -> Uncertainty {
    Uncertainty {
        sigma_dps: curves(u, residuals, true),
        ..*u
    }
}

/// The oracle: σ(t) whose curves are fitted on `held_out` itself (inside the envelope), checked on
/// it. Near 95 % when σ's form (per class and knot, every axis alike) can describe these residuals
/// at all, whatever the calibration showed.
pub fn oracle_coverage(u: &Uncertainty, held_out: &[Residuals]) -> [Coverage; ACTIVATION_CLASSES] {
    coverage(&refitted_on(u, held_out), held_out)
}

/// The split-half oracle: σ(t)'s curves fitted on every other activation of `held_out` and checked
/// on the rest, then the other way round (the counts summed). How far the coverage of a σ fitted
/// on residuals of the very same kind scatters at this many activations: no σ from any
/// calibration can be expected to land closer to 95 % than this.
pub fn split_half_coverage(
    u: &Uncertainty,
    held_out: &[Residuals],
) -> [Coverage; ACTIVATION_CLASSES] {
    let half = |parity: usize| -> Vec<Residuals> {
        held_out
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 2 == parity)
            .map(|(_, r)| r.clone())
            .collect()
    };
    let (even, odd) = (half(0), half(1));
    let mut out = coverage(&refitted_on(u, &even), &odd);
    let other = coverage(&refitted_on(u, &odd), &even);
    for (cell, more) in out.iter_mut().zip(other) {
        cell.axis_activations += more.axis_activations;
        cell.widened_axis_activations += more.widened_axis_activations;
        cell.samples += more.samples;
        cell.inside += more.inside;
        cell.widened_samples += more.widened_samples;
        cell.widened_inside += more.widened_inside;
    }
    out
}

/// How many held-out residuals fell within ±2σ, for one class.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Coverage {
    /// The class's name ([`ActivationClass::name`]).
    pub class: &'static str,
    /// Activation × axis pairs of the class.
    pub axis_activations: usize,
    /// Residual samples (every [`EVERY_MS`], every axis).
    pub samples: usize,
    /// Of them, within ±2σ(t).
    pub inside: usize,
    /// Of the activation × axis pairs, those outside the calibrated envelope, where σ widens.
    pub widened_axis_activations: usize,
    /// Of the samples, those of activation × axis pairs outside the calibrated envelope, where σ
    /// widens (ambient outside the set points, residual heat beyond the calibration's most).
    pub widened_samples: usize,
    /// Of them, within ±2σ(t).
    pub widened_inside: usize,
}

impl Coverage {
    /// The share within ±2σ (NaN for no samples).
    pub fn share(&self) -> f64 {
        self.inside as f64 / self.samples as f64
    }

    /// The share within ±2σ where σ widens (NaN for no samples).
    pub fn widened_share(&self) -> f64 {
        self.widened_inside as f64 / self.widened_samples as f64
    }

    /// The share within ±2σ inside the envelope (NaN for no samples).
    pub fn unwidened_share(&self) -> f64 {
        (self.inside - self.widened_inside) as f64 / (self.samples - self.widened_samples) as f64
    }
}

/// Per class, how many of `held_out`'s residuals lie within ±2σ(t) of `uncertainty`, as firmware
/// computes σ (drift-core, f32).
pub fn coverage(
    uncertainty: &Uncertainty,
    held_out: &[Residuals],
) -> [Coverage; ACTIVATION_CLASSES] {
    let mut out = ActivationClass::ALL.map(|class| Coverage {
        class: class.name(),
        axis_activations: 0,
        widened_axis_activations: 0,
        samples: 0,
        inside: 0,
        widened_samples: 0,
        widened_inside: 0,
    });
    for r in held_out {
        let state: SigmaState = uncertainty.start(&r.switch_on);
        for (class, widening) in state.class.iter().zip(state.widening_dps) {
            out[*class as usize].axis_activations += 1;
            if widening > 0.0 {
                out[*class as usize].widened_axis_activations += 1;
            }
        }
        for &(ms, residual) in &r.samples {
            let sigma = uncertainty.sigma_dps(&state, ms);
            for (((class, value), sigma), widening) in state
                .class
                .iter()
                .zip(residual)
                .zip(sigma)
                .zip(state.widening_dps)
            {
                let cell = &mut out[*class as usize];
                let within = usize::from(value.abs() <= 2.0 * sigma);
                cell.samples += 1;
                cell.inside += within;
                if widening > 0.0 {
                    cell.widened_samples += 1;
                    cell.widened_inside += within;
                }
            }
        }
    }
    out
}

/// How often one split's residuals fell within ±2σ, per class.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SplitCoverage {
    /// The split's name ([`Split::name`]).
    pub split: &'static str,
    /// Per class, in [`ActivationClass::ALL`] order.
    pub classes: [Coverage; ACTIVATION_CLASSES],
    /// Per class, σ's curves fitted on this split's own residuals ([`oracle_coverage`]).
    pub oracle: [Coverage; ACTIVATION_CLASSES],
    /// Per class, σ's curves fitted on half of this split's activations and checked on the other
    /// half ([`split_half_coverage`]).
    pub split_half: [Coverage; ACTIVATION_CLASSES],
}

/// One unit's σ(t) and its coverage on held-out activations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitUncertainty {
    /// The unit.
    pub unit_id: String,
    /// Calibration activations (held-out repeats) σ was fitted on.
    pub fitted_on_activations: usize,
    /// The fitted σ(t), as drift-core reads it.
    pub sigma: Uncertainty,
    /// Per held-out split (validation, field), how often its residuals fell within ±2σ.
    pub coverage: Vec<SplitCoverage>,
}

/// Per unit of `fitted` with held-out-repeat residuals: σ(t) fitted on them and checked on the
/// validation and field residuals. A unit without held-out repeats (one repeat, or refits off)
/// gets none: σ fitted on the tables' own calibration data would be too small.
pub fn per_unit(fitted: &[FittedUnit], residuals: &[(Split, Residuals)]) -> Vec<UnitUncertainty> {
    let mut out = Vec::new();
    for unit in fitted {
        let of = |split: Split| -> Vec<Residuals> {
            residuals
                .iter()
                .filter(|(s, r)| *s == split && r.unit_id == unit.unit_id)
                .map(|(_, r)| r.clone())
                .collect()
        };
        let calibration = of(Split::HeldOutRepeat);
        if calibration.is_empty() {
            continue;
        }
        let turn_on = unit.recommended.axes.each_ref().map(|a| a.turn_on.clone());
        let sigma = fit(&calibration, &turn_on);
        let coverage = [Split::Validation, Split::Field]
            .into_iter()
            .filter_map(|split| {
                let held_out = of(split);
                (!held_out.is_empty()).then(|| SplitCoverage {
                    split: split.name(),
                    classes: coverage(&sigma, &held_out),
                    oracle: oracle_coverage(&sigma, &held_out),
                    split_half: split_half_coverage(&sigma, &held_out),
                })
            })
            .collect();
        out.push(UnitUncertainty {
            unit_id: unit.unit_id.clone(),
            fitted_on_activations: calibration.len(),
            sigma,
            coverage,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn residual(set_point: f64, residual_heat: f32, values: &[(u32, f32)]) -> Residuals {
        let switch_on = SwitchOn {
            switch_on_celsius: set_point as f32 + residual_heat,
            ambient_celsius: set_point as f32,
            residual_heat_celsius: residual_heat,
            remaining: 0.0,
            known: true,
        };
        Residuals {
            unit_id: "U".into(),
            set_point_celsius: set_point,
            switch_on: [switch_on; 3],
            mean_uncorrected_dps: [set_point * 0.001, 0.0, 0.0],
            samples: values.iter().map(|&(ms, v)| (ms, [v, -v, v])).collect(),
        }
    }

    /// Turn-on biases whose slope in residual heat is largest (in magnitude) on Y.
    fn turn_on() -> [TurnOn; 3] {
        [(2.0, 0.001), (2.5, -0.003), (2.0, 0.002)].map(|(most, slope)| TurnOn {
            most_residual_heat_celsius: most,
            dps_per_residual_celsius: slope,
            ..TurnOn::default()
        })
    }

    /// Residuals drawn from a normal distribution whose σ falls after switch-on and is twice as
    /// large for warm restarts: the fit finds each class's σ at the knots, and held-out draws
    /// from the same distribution fall within ±2σ about 95 % of the time.
    #[test]
    fn sigma_is_fitted_per_class_and_covers_draws_of_the_same_distribution() {
        let mut state = 7u64;
        let mut normal = move || {
            // Box–Muller on a 64-bit LCG: deterministic, no dependency.
            let mut uniform = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (u1, u2) = (uniform(), uniform());
            ((-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()) as f32
        };
        let true_sigma = |ms: u32, warm: bool| {
            let base = if ms < 10_000 { 0.004 } else { 0.001 };
            if warm {
                2.0 * base
            } else {
                base
            }
        };
        let mut draw = |set_point: f64, warm: bool| {
            let values: Vec<(u32, f32)> = (0..1200)
                .map(|i| {
                    let ms = i * 100;
                    (ms, true_sigma(ms, warm) * normal())
                })
                .collect();
            residual(set_point, if warm { 2.0 } else { 0.0 }, &values)
        };
        let calibration: Vec<Residuals> = (0..40)
            .map(|i| draw(if i % 2 == 0 { 30.0 } else { 40.0 }, i % 4 < 2))
            .collect();
        let u = fit(&calibration, &turn_on());
        u.validate().unwrap();
        assert_eq!((u.ambient_min_celsius, u.ambient_max_celsius), (30.0, 40.0));
        assert_eq!(u.most_residual_heat_celsius, [2.0, 2.5, 2.0]);
        assert_eq!(u.per_residual_celsius_beyond_dps, 0.003);
        assert!((u.per_celsius_outside_dps - 0.001).abs() < 1e-6);
        let late_cold = u.sigma_dps[0][6];
        let late_warm = u.sigma_dps[1][6];
        assert!((late_cold / 0.001 - 1.0).abs() < 0.1, "{u:?}");
        assert!((late_warm / 0.002 - 1.0).abs() < 0.1, "{u:?}");
        assert!(u.sigma_dps[1][1] > 3.0 * late_warm, "{u:?}");
        let held_out: Vec<Residuals> = (0..20).map(|i| draw(33.0, i % 2 == 0)).collect();
        for cell in coverage(&u, &held_out) {
            assert_eq!(cell.axis_activations, 30, "{cell:?}");
            assert!((0.93..=0.97).contains(&cell.share()), "{cell:?}");
            assert_eq!(cell.widened_samples, 0, "inside the envelope: {cell:?}");
        }
    }

    /// Held-out residuals half again as wide as the calibration's: σ fitted on the calibration
    /// under-covers them, the oracle (σ's curves fitted on them) covers about 95 %, and the
    /// split-half oracle counts every held-out pair once.
    #[test]
    fn the_oracles_fit_the_held_out_residuals_themselves() {
        let mut state = 11u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) as f32
        };
        // Uniform on ±w: its 95 % quantile of |x| is 0.95 w, whatever w.
        let mut draw = |set_point: f64, width: f32| {
            let values: Vec<(u32, f32)> = (0..600)
                .map(|i| (i * 100, width * (2.0 * uniform() - 1.0)))
                .collect();
            residual(set_point, 0.0, &values)
        };
        let calibration: Vec<Residuals> = (0..20)
            .map(|i| draw(if i % 2 == 0 { 30.0 } else { 40.0 }, 0.002))
            .collect();
        let held_out: Vec<Residuals> = (0..20).map(|_| draw(33.0, 0.003)).collect();
        let u = fit(&calibration, &turn_on());
        let cold = ActivationClass::Cold as usize;
        let fitted = coverage(&u, &held_out)[cold];
        let oracle = oracle_coverage(&u, &held_out)[cold];
        let halves = split_half_coverage(&u, &held_out)[cold];
        assert!(fitted.share() < 0.7, "{fitted:?}");
        assert!((0.94..=0.96).contains(&oracle.share()), "{oracle:?}");
        assert!((0.93..=0.97).contains(&halves.share()), "{halves:?}");
        assert_eq!(halves.axis_activations, fitted.axis_activations);
        assert_eq!(halves.samples, fitted.samples);
    }

    #[test]
    fn an_empty_class_takes_the_pooled_value() {
        let calibration = [residual(30.0, 0.0, &[(0, 0.01), (100_000, 0.002)])];
        let u = fit(&calibration, &turn_on());
        assert_eq!(u.sigma_dps[1], u.sigma_dps[0]);
        assert!(u.sigma_dps[0][0] > 0.0);
        u.validate().unwrap();
    }

    #[test]
    fn each_time_goes_to_its_nearest_knot() {
        assert_eq!(knot_of(0), 0);
        assert_eq!(knot_of(999), 0);
        assert_eq!(knot_of(1_001), 1);
        assert_eq!(knot_of(7_499), 2);
        assert_eq!(knot_of(u32::MAX), SIGMA_KNOTS - 1);
    }
}
