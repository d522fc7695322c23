//! Each axis's temperature rate at switch-on, measured on the calibration activations: where the
//! extended model's temperature-rate filter starts (`drift_core::SwitchOnRate`).
//!
//! The heating is a cold start's rate at switch-on, read from its first seconds. The cooling is
//! never recorded directly (the unit is off), but it shows after switch-on: the unit's thermal
//! network is linear, so a warm start's temperature is a cold start's heating (at the same ambient)
//! plus the cooling of the heat it switched on with, and a warm start's rate at switch-on less a
//! cold start's is the cooling rate, whatever the heating does. Only what firmware has at switch-on
//! goes in: the residual heat and the fraction of the switch-off heat left
//! (`drift_core::SwitchOn`), never a clock and never the simulator's truth.

use drift_core::{Previous, Settings, SwitchOn, SwitchOnRate};
use drift_recording::Segment;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::Serialize;

use crate::candidates::StartRates;
use crate::keying::Keying;
use drift_evaluate::evaluate::{sample_at, switch_on_raw};
use drift_fit::settings::FitSettings;

/// Each axis's switch-on estimate, as `power_on_after` makes it from the raw switch-on readings
/// `switch_on_raw` and what was kept before (`previous`; `None`: as `power_on`, nothing known).
pub fn switch_ons(
    core: &Settings,
    switch_on_raw: [f32; 3],
    previous: Option<[Previous; 3]>,
) -> [SwitchOn; 3] {
    std::array::from_fn(|a| {
        SwitchOn::estimate(core.celsius(switch_on_raw[a]), previous.map(|p| p[a]))
    })
}

/// Each axis's temperature rate at switch-on by `rates`, °C/s, for these switch-on readings and
/// history: the sensor's, and the element's (the heating left out), where a rate candidate's filter
/// starts as the firmware's would.
pub fn start_rates(
    rates: &[SwitchOnRate; 3],
    core: &Settings,
    switch_on_raw: [f32; 3],
    previous: Option<[Previous; 3]>,
) -> StartRates {
    let starts = switch_ons(core, switch_on_raw, previous);
    StartRates {
        sensor: std::array::from_fn(|a| rates[a].rate(&starts[a])),
        element: std::array::from_fn(|a| without_heating(rates[a]).rate(&starts[a])),
    }
}

/// `rate` for a node that has not started heating at switch-on: the cooling alone.
pub fn without_heating(rate: SwitchOnRate) -> SwitchOnRate {
    SwitchOnRate {
        heating_celsius_per_s: 0.0,
        ..rate
    }
}

/// The first seconds whose curve measures the cooling, ms: long against the sensor's noise (10⁴
/// samples at 1 kHz), short enough that a parabola follows the cooling's bend (its fastest part
/// leaves over ~90 s). The heating within it cancels against the cold start's.
const COOLING_WINDOW_MS: u32 = 10_000;
/// The first seconds whose curve measures the heating, ms. The heating rate falls steadily as the
/// heat spreads from the ASIC (in the simulator 0.156 °C/s at switch-on, 0.152 at 0.5 s, 0.142 at
/// 2 s), so a parabola over 2 s gives the rate at switch-on, where a mean slope over 2 s is the
/// rate at 1 s (4–7 % lower).
const HEATING_WINDOW_MS: u32 = 2_000;
/// Residual heat below which a start is cold: the reference for the warm starts, °C.
const COLD_BELOW_CELSIUS: f32 = 0.05;
/// Residual heat from which a start measures the cooling, °C: below it the slope is mostly noise.
const WARM_FROM_CELSIUS: f32 = 0.2;
/// How far a cold reference's ambient may be from the warm start's, °C.
const SAME_AMBIENT_CELSIUS: f32 = 1.5;
/// Fewest warm starts an axis needs for a fit.
const MIN_WARM_STARTS: usize = 3;

/// One axis's measured switch-on rate, for reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SwitchOnRateFit {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Cold starts measured.
    pub cold_starts: usize,
    /// Warm starts measured (with a cold start at the same ambient).
    pub warm_starts: usize,
    /// The fit (at rest without cold starts; no cooling with fewer than three warm starts).
    #[serde(flatten)]
    pub rate: SwitchOnRate,
    /// RMS of the warm starts' measured cooling rates about the fit, °C/s.
    pub cooling_rms_error_celsius_per_s: f64,
}

/// One activation's start: per axis the switch-on estimate and the temperature's rate at switch-on
/// over the heating's and the cooling's first seconds.
struct Start {
    switch_on: [SwitchOn; 3],
    heating_rate: [f64; 3],
    cooling_rate: [f64; 3],
}

fn start(segment: &Segment, kept: [Previous; 3], core: &Settings, settings: &FitSettings) -> Start {
    let (heating_rate, cooling_rate) = rates_at_switch_on(segment, core);
    Start {
        switch_on: switch_ons(core, switch_on_raw(segment, settings), Some(kept)),
        heating_rate,
        cooling_rate,
    }
}

/// A least-squares parabola through (time since switch-on, temperature), kept as its normal
/// equations so that one pass over the samples can feed two windows.
#[derive(Clone, Copy)]
struct Parabola {
    normal: Matrix3<f64>,
    rhs: Vector3<f64>,
}

impl Parabola {
    const EMPTY: Self = Self {
        normal: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        rhs: Vector3::new(0.0, 0.0, 0.0),
    };

    fn add(&mut self, t: f64, celsius: f64) {
        let row = Vector3::new(1.0, t, t * t);
        self.normal += row * row.transpose();
        self.rhs += row * celsius;
    }

    /// The parabola's slope at switch-on, °C/s: the rate at t = 0, where a mean slope over the
    /// window would be the rate at its middle (NaN with fewer than four readings or no spread).
    fn slope_at_switch_on(&self) -> f64 {
        if self.normal[(0, 0)] < 4.0 {
            return f64::NAN;
        }
        let normal = DMatrix::from_iterator(3, 3, self.normal.iter().copied());
        let rhs = DVector::from_iterator(3, self.rhs.iter().copied());
        drift_fit::regression::solve(normal, &rhs).map_or(f64::NAN, |c| c[1])
    }
}

/// Per axis, the temperature's rate at switch-on from its least-squares parabola over the
/// heating's and the cooling's first seconds, °C/s: one pass over the samples, the shorter
/// window's sums taken on the way.
fn rates_at_switch_on(segment: &Segment, core: &Settings) -> ([f64; 3], [f64; 3]) {
    let mut heating = [Parabola::EMPTY; 3];
    let mut cooling = [Parabola::EMPTY; 3];
    for i in 0..segment.len() {
        let sample = sample_at(segment, i);
        if sample.since_power_on_ms > COOLING_WINDOW_MS {
            break;
        }
        let in_heating = sample.since_power_on_ms <= HEATING_WINDOW_MS;
        let t = f64::from(sample.since_power_on_ms) / 1000.0;
        for ((heating, cooling), raw) in heating
            .iter_mut()
            .zip(&mut cooling)
            .zip(sample.temperature_raw)
        {
            let celsius = f64::from(core.celsius(raw));
            if celsius.is_finite() {
                cooling.add(t, celsius);
                if in_heating {
                    heating.add(t, celsius);
                }
            }
        }
    }
    (
        heating.map(|p| p.slope_at_switch_on()),
        cooling.map(|p| p.slope_at_switch_on()),
    )
}

/// Fits each axis's switch-on rate on the `calibration` activations, with what firmware kept
/// before each (`keying`): the heating is the cold starts' mean rate at switch-on; the cooling,
/// `residual_heat · (a + b · remaining)`, is least squares over the warm starts, each measured
/// against the cold start nearest in ambient. Without cold starts the filter starts at rest. An
/// axis with fewer than three warm starts, or whose fit would have the unit warm itself while
/// off, gets no cooling (or a single rate per °C, when that alone is positive).
pub fn fit_switch_on_rate(
    calibration: &[&Segment],
    keying: &Keying,
    core: &Settings,
    settings: &FitSettings,
) -> [SwitchOnRateFit; 3] {
    let starts: Vec<Start> = calibration
        .iter()
        .map(|s| start(s, keying.kept(s), core, settings))
        .collect();
    std::array::from_fn(|a| {
        let cold_starts: Vec<&Start> = starts
            .iter()
            .filter(|s| s.switch_on[a].residual_heat_celsius < COLD_BELOW_CELSIUS)
            .collect();
        let heating: Vec<f64> = cold_starts
            .iter()
            .map(|s| s.heating_rate[a])
            .filter(|rate| rate.is_finite())
            .collect();
        let colds: Vec<(f32, f64)> = cold_starts
            .iter()
            .map(|s| (s.switch_on[a].ambient_celsius, s.cooling_rate[a]))
            .filter(|(ambient, rate)| ambient.is_finite() && rate.is_finite())
            .collect();
        // (residual heat, remaining, measured cooling rate)
        let warm: Vec<(f64, f64, f64)> = starts
            .iter()
            .filter(|s| s.switch_on[a].known)
            .filter(|s| s.switch_on[a].residual_heat_celsius >= WARM_FROM_CELSIUS)
            .filter_map(|s| {
                let on = &s.switch_on[a];
                let (distance, cold_rate) = colds
                    .iter()
                    .map(|(ambient, rate)| ((ambient - on.ambient_celsius).abs(), *rate))
                    .min_by(|x, y| x.0.total_cmp(&y.0))?;
                let rate = s.cooling_rate[a] - cold_rate;
                (distance <= SAME_AMBIENT_CELSIUS && rate.is_finite()).then_some((
                    f64::from(on.residual_heat_celsius),
                    f64::from(on.remaining),
                    rate,
                ))
            })
            .collect();
        let mut fit = fit_cooling(a, &warm);
        fit.cold_starts = heating.len();
        if heating.is_empty() {
            return SwitchOnRateFit {
                rate: SwitchOnRate::AT_REST,
                ..fit
            };
        }
        fit.rate.heating_celsius_per_s =
            (heating.iter().sum::<f64>() / heating.len() as f64) as f32;
        fit
    })
}

/// Least squares of the cooling `rate = −heat · (a + b · remaining)` over `warm`, kept physical
/// (no heating yet).
fn fit_cooling(axis: usize, warm: &[(f64, f64, f64)]) -> SwitchOnRateFit {
    let fit = |a: f64, b: f64| {
        let squares: f64 = warm
            .iter()
            .map(|&(heat, remaining, rate)| (rate + heat * (a + b * remaining)).powi(2))
            .sum();
        #[allow(clippy::cast_possible_truncation)]
        let rate = SwitchOnRate {
            heating_celsius_per_s: 0.0,
            cooling_per_second: a as f32,
            cooling_per_second_per_remaining: b as f32,
        };
        SwitchOnRateFit {
            axis: ["X", "Y", "Z"][axis],
            cold_starts: 0,
            warm_starts: warm.len(),
            rate,
            cooling_rms_error_celsius_per_s: (squares / warm.len().max(1) as f64).sqrt(),
        }
    };
    if warm.len() < MIN_WARM_STARTS {
        return fit(0.0, 0.0);
    }
    let rows: Vec<Vec<f64>> = warm
        .iter()
        .map(|&(heat, remaining, _)| vec![-heat, -heat * remaining])
        .collect();
    let rates: Vec<f64> = warm.iter().map(|w| w.2).collect();
    let both = drift_fit::regression::least_squares(&rows, &rates);
    if let [a, b] = both[..] {
        if a >= 0.0 && a + b >= 0.0 {
            return fit(a, b);
        }
    }
    // One rate per °C: Σ rate·(−heat) / Σ heat².
    let (num, den) = warm.iter().fold((0.0, 0.0), |(n, d), &(heat, _, rate)| {
        (n - rate * heat, d + heat * heat)
    });
    let a = if den > 0.0 { num / den } else { 0.0 };
    if a > 0.0 && a.is_finite() {
        fit(a, 0.0)
    } else {
        fit(0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rate_at_switch_on_is_the_parabola_s_slope_at_zero_not_the_window_s_mean() {
        // A heating rate falling from 0.156 °C/s as the heat spreads, sampled at 100 Hz for 2 s:
        // the mean slope would be the rate at 1 s (0.148).
        let mut parabola = Parabola::EMPTY;
        for i in 0..=200 {
            let t = f64::from(i) / 100.0;
            parabola.add(t, 25.0 + 0.156 * t - 0.004 * t * t);
        }
        assert!((parabola.slope_at_switch_on() - 0.156).abs() < 1e-9);
        let mut three = Parabola::EMPTY;
        for t in [0.0, 0.01, 0.02] {
            three.add(t, 25.0);
        }
        assert!(three.slope_at_switch_on().is_nan());
    }

    #[test]
    fn a_two_speed_cooling_is_recovered_from_its_warm_starts() {
        // Rates from a unit that cools at 1/250 s per °C plus 1/100 s per unit of remaining heat.
        let warm: Vec<(f64, f64, f64)> = [
            (2.5, 0.42),
            (1.6, 0.34),
            (1.0, 0.2),
            (0.6, 0.1),
            (0.3, 0.05),
        ]
        .iter()
        .map(|&(heat, remaining)| (heat, remaining, -heat * (0.004 + 0.01 * remaining)))
        .collect();
        let fit = fit_cooling(0, &warm).rate;
        assert!((fit.cooling_per_second - 0.004).abs() < 1e-6, "{fit:?}");
        assert!(
            (fit.cooling_per_second_per_remaining - 0.01).abs() < 1e-6,
            "{fit:?}"
        );
        assert!(fit_cooling(0, &warm).cooling_rms_error_celsius_per_s < 1e-9);
    }

    #[test]
    fn too_few_or_warming_starts_get_no_cooling() {
        let fit = fit_cooling(1, &[(1.0, 0.3, -0.01), (2.0, 0.4, -0.02)]);
        assert_eq!(fit.rate, SwitchOnRate::AT_REST);
        // Rates that say the unit warmed while off: not physical, at rest.
        let warming: Vec<(f64, f64, f64)> = (1..6)
            .map(|i| (f64::from(i) * 0.5, 0.3, 0.001 * f64::from(i)))
            .collect();
        assert_eq!(fit_cooling(2, &warming).rate, SwitchOnRate::AT_REST);
    }
}
