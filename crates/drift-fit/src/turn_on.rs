//! The recommended model's turn-on bias: `q(T_on) + h · residual heat`, fitted by least squares on
//! every calibration activation's initial bias, cold and warm, at every set point.
//!
//! The paper keeps one initial bias per calibration ambient (its fully cooled starts) and reads
//! between them linearly; the calibration's series also measure warm starts and switch-ons between
//! and above the ambients, and a fit across all of them gives the offset a unit in use starts from.
//! The residual heat is estimated as firmware estimates it (`drift_core::SwitchOn`), from what it
//! kept of the series' previous activation; a series' first activation follows a full cool-down.
//! The most residual heat seen is stored with the slope: firmware holds a larger one there.

use std::collections::BTreeMap;

use drift_core::{Previous, SwitchOn, TurnOn, MAX_POLYNOMIAL_COEFFICIENTS};

use crate::analyse::Analysed;
use crate::baselines::{
    axis_polynomial, band_key, cross_validated, range_of, Gram, Normalise, MAX_TURN_ON_DEGREE,
};
use crate::parallel::per_axis;

/// The residual heat (°C) each activation switched on with on `axis`, in `activations`' order:
/// the estimate of [`SwitchOn::estimate`] from the previous activation of the same calibration
/// series (unit, set point, series, repeat), in activation order; 0 for a series' first.
pub fn residual_heats(activations: &[&Analysed], axis: usize) -> Vec<f64> {
    let mut order: Vec<usize> = (0..activations.len()).collect();
    let key = |a: &Analysed| {
        (
            a.labels.unit_id.clone(),
            (a.labels.set_point_celsius * 1000.0).round() as i64,
            a.labels.series,
            a.labels.repeat,
            a.labels.activation,
        )
    };
    order.sort_by_key(|&i| key(activations[i]));
    let mut heats = vec![0.0; activations.len()];
    let mut previous: Option<((String, i64, u32, u32), Previous)> = None;
    for i in order {
        let a = activations[i];
        let (unit, set_point, series, repeat, _) = key(a);
        let series_key = (unit, set_point, series, repeat);
        let on = a.switch_on_celsius[axis] as f32;
        let kept = previous
            .as_ref()
            .filter(|(k, _)| *k == series_key)
            .map(|(_, p)| *p)
            .unwrap_or(Previous::COOLED[axis]);
        let estimate = SwitchOn::estimate(on, Some(kept));
        heats[i] = f64::from(estimate.residual_heat_celsius);
        let last_rise = a.rise_celsius[axis]
            .iter()
            .rev()
            .copied()
            .find(|r| r.is_finite())
            .unwrap_or(0.0);
        previous = Some((
            series_key,
            Previous {
                ambient_celsius: estimate.ambient_celsius,
                switch_off_celsius: on + last_rise,
            },
        ));
    }
    heats
}

/// The span of the activations' switch-on temperatures on `axis` (°C), widened to 1 °C around one
/// temperature: `q`'s fitted range, beyond which firmware continues it along its tangent rather than
/// trust a cubic's curvature where no switch-on was seen.
fn switch_on_range(activations: &[&Analysed], axis: usize) -> [f64; 2] {
    let (low, high) = activations
        .iter()
        .map(|a| a.switch_on_celsius[axis])
        .filter(|t| t.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
            (lo.min(t), hi.max(t))
        });
    if high - low >= 1.0 {
        [low, high]
    } else if low.is_finite() {
        let mid = 0.5 * (low + high);
        [mid - 0.5, mid + 0.5]
    } else {
        range_of(activations, axis)
    }
}

/// The turn-on bias per axis: basis `1, heat, x_on, x_on², x_on³` (`x_on` the switch-on
/// temperature normalised over the calibration's switch-on temperatures), `q`'s order up to the cubic chosen by
/// cross-validation over held-out switch-on temperature bands, as the relative baseline's.
pub fn turn_on(activations: &[&Analysed]) -> [TurnOn; 3] {
    per_axis(|axis| {
        let range = switch_on_range(activations, axis);
        let normalise = Normalise::over(range);
        let heats = residual_heats(activations, axis);
        let mut groups: BTreeMap<i64, Gram> = BTreeMap::new();
        let mut phi = [0.0; MAX_TURN_ON_DEGREE + 2];
        for (a, &heat) in activations.iter().zip(&heats) {
            let on = a.switch_on_celsius[axis];
            let (x_on, bias) = (normalise.apply(on), a.initial_bias_dps[axis]);
            if !(x_on.is_finite() && bias.is_finite() && heat.is_finite()) {
                continue;
            }
            phi[0] = 1.0;
            phi[1] = heat;
            let mut power = 1.0;
            for value in phi.iter_mut().skip(2) {
                power *= x_on;
                *value = power;
            }
            groups.entry(band_key(on)).or_default().add(&phi, bias);
        }
        let groups: Vec<Gram> = groups.into_values().collect();
        let fitted = cross_validated(&groups, 2, MAX_TURN_ON_DEGREE + 2)
            .or_else(|| cross_validated(&groups, 1, 1));
        let (columns, c) = fitted.unwrap_or((1, vec![0.0]));
        // c = [constant, heat slope, x¹ …]: q's coefficients without the heat's.
        let mut q = vec![c.first().copied().unwrap_or(0.0)];
        q.extend(c.iter().skip(2).take(MAX_POLYNOMIAL_COEFFICIENTS - 1));
        let slope = if columns >= 2 {
            c.get(1).copied().unwrap_or(0.0)
        } else {
            0.0
        };
        let most_heat = heats
            .iter()
            .copied()
            .filter(|h| h.is_finite())
            .fold(0.0, f64::max);
        TurnOn {
            polynomial: axis_polynomial(range, &q),
            dps_per_residual_celsius: slope as f32,
            most_residual_heat_celsius: most_heat as f32,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Series of three activations at 30 and 40 °C: each switches on warmer than the one before
    /// (residual heat 0, 1.5, 2.5 °C over the series' ambient) and ends 4 °C above its switch-on.
    /// Turn-on bias `0.002·(T_on − 30) − 0.004·heat`.
    fn activations() -> Vec<Analysed> {
        let mut out = Vec::new();
        for set_point in [30.0, 40.0] {
            for series in 1..=2u32 {
                for (activation, heat) in [(1u32, 0.0), (2, 1.5), (3, 2.5)] {
                    let on: f64 = set_point + heat + 0.2 * f64::from(series);
                    let rise: Vec<f32> = (0..100).map(|i| i as f32 * 0.04).collect();
                    let bias = 0.002 * (on - 30.0) - 0.004 * heat;
                    out.push(Analysed {
                        labels: drift_recording::SegmentLabels {
                            unit_id: "U".into(),
                            set_point_celsius: set_point,
                            session_set_point_celsius: None,
                            series_kind: drift_recording::SeriesKind::Protocol,
                            series,
                            repeat: 1,
                            activation,
                            interval_min: Some(1.0),
                            off_before_s: Some(60.0),
                        },
                        grid_ms: 10,
                        sample_rate_hz: 1000,
                        switch_on_raw: [(on * 200.0) as f32; 3],
                        switch_on_celsius: [on; 3],
                        initial_bias_dps: [bias; 3],
                        drift_dps: [vec![0.0; 100], vec![0.0; 100], vec![0.0; 100]],
                        rise_celsius: [rise.clone(), rise.clone(), rise],
                        temperature_scale: drift_recording::TemperatureScale::default(),
                    });
                }
            }
        }
        out
    }

    #[test]
    fn residual_heat_is_what_firmware_would_estimate_within_a_series() {
        let data = activations();
        let refs: Vec<&Analysed> = data.iter().collect();
        let heats = residual_heats(&refs, 0);
        for (a, heat) in data.iter().zip(&heats) {
            let want = match a.labels.activation {
                1 => 0.0,
                2 => 1.5,
                _ => 2.5,
            };
            assert!((heat - want).abs() < 1e-4, "{:?}: {heat}", a.labels);
        }
    }

    #[test]
    fn the_turn_on_fit_separates_the_temperature_from_the_residual_heat() {
        let data = activations();
        let refs: Vec<&Analysed> = data.iter().collect();
        let [x, ..] = turn_on(&refs);
        assert!((x.dps_per_residual_celsius - -0.004).abs() < 2e-4, "{x:?}");
        let (q, outside) = x.polynomial.evaluate(35.0, 0.5);
        assert!(!outside);
        assert!((q - 0.01).abs() < 5e-4, "q(35) = {q}");
    }
}
