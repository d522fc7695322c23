//! The two baselines, fitted on the same calibration activations as the paper's tables: bias as a
//! polynomial of the absolute sensor temperature, no heating dynamics.

use drift_core::{PolynomialAxis, PolynomialTables, Settings, MAX_POLYNOMIAL_COEFFICIENTS};
use nalgebra::{DMatrix, DVector};

use crate::analyse::Analysed;

/// Calibration data of one axis as (temperature °C, low-frequency rate °/s) pairs on the grid.
fn pairs<'a>(
    activations: &'a [&'a Analysed],
    axis: usize,
) -> impl Iterator<Item = (f64, f64)> + 'a {
    activations.iter().flat_map(move |a| {
        a.rise_celsius[axis]
            .iter()
            .zip(&a.drift_dps[axis])
            .map(move |(&rise, &drift)| {
                (
                    a.switch_on_celsius[axis] + f64::from(rise),
                    a.initial_bias_dps[axis] + f64::from(drift),
                )
            })
    })
}

/// The normalised variable `x = (T − mid) / half_span` over `range`.
fn normalise(range: [f64; 2], t: f64) -> f64 {
    let half = 0.5 * (range[1] - range[0]);
    (t - (range[0] + half)) / half
}

fn range_of(activations: &[&Analysed], axis: usize) -> [f64; 2] {
    let (lo, hi) = pairs(activations, axis)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (t, _)| {
            (lo.min(t), hi.max(t))
        });
    if hi > lo {
        [lo, hi]
    } else {
        [lo - 0.5, lo + 0.5]
    }
}

fn axis_polynomial(range: [f64; 2], coefficients: &[f64]) -> PolynomialAxis {
    let mut axis = PolynomialAxis {
        range_celsius: [range[0] as f32, range[1] as f32],
        ..PolynomialAxis::default()
    };
    for &c in coefficients.iter().take(MAX_POLYNOMIAL_COEFFICIENTS) {
        // Capacity is checked by the caller (degree ≤ 7).
        let _ = axis.coefficients.push(c as f32);
    }
    axis
}

/// Solves the (small) least-squares or interpolation system `V c = y` in the normalised variable.
fn solve(xs: &[f64], ys: &[f64], degree: usize) -> Vec<f64> {
    let columns = degree + 1;
    // Normal equations accumulated in one pass: O(n · degree), no n × degree matrix in memory.
    // Entry (r, c) is the sum of x^(r+c), so the 2·degree + 1 power sums are accumulated once (in
    // the data's order, the same additions an entry-by-entry accumulation would make).
    let mut power_sums = vec![0.0; 2 * columns];
    let mut rhs = DVector::<f64>::zeros(columns);
    for (&x, &y) in xs.iter().zip(ys) {
        let mut p = 1.0;
        for (k, sum) in power_sums.iter_mut().enumerate() {
            if k < columns {
                rhs[k] += p * y;
            }
            *sum += p;
            p *= x;
        }
    }
    let normal = DMatrix::<f64>::from_fn(columns, columns, |r, c| power_sums[r + c]);
    normal
        .lu()
        .solve(&rhs)
        .map(|v| v.iter().copied().collect())
        .unwrap_or_else(|| vec![ys.iter().sum::<f64>() / ys.len().max(1) as f64])
}

/// The paper's "standard" calibration: per set point one calibration point (mean sensor temperature,
/// mean bias over its activations), and the Lagrange polynomial through them (degree = points − 1).
pub fn standard(by_set_point: &[Vec<&Analysed>], settings: Settings) -> PolynomialTables {
    let axes = [0, 1, 2].map(|axis| {
        let all: Vec<&Analysed> = by_set_point.iter().flatten().copied().collect();
        let range = range_of(&all, axis);
        let points: Vec<(f64, f64)> = by_set_point
            .iter()
            .filter(|group| !group.is_empty())
            .map(|group| {
                let (n, t, b) = pairs(group, axis).fold((0.0, 0.0, 0.0), |(n, t, b), (ti, bi)| {
                    (n + 1.0, t + ti, b + bi)
                });
                (t / n, b / n)
            })
            .collect();
        let xs: Vec<f64> = points.iter().map(|p| normalise(range, p.0)).collect();
        let ys: Vec<f64> = points.iter().map(|p| p.1).collect();
        // Through every point: as many coefficients as points (capped at the image's capacity).
        let degree = points.len().clamp(1, MAX_POLYNOMIAL_COEFFICIENTS) - 1;
        axis_polynomial(range, &solve(&xs, &ys, degree))
    });
    PolynomialTables { settings, axes }
}

/// The PX4/ArduPilot practice: a least-squares polynomial of the given degree per axis over every
/// calibration grid point.
pub fn least_squares(
    activations: &[&Analysed],
    degree: usize,
    settings: Settings,
) -> PolynomialTables {
    let axes = [0, 1, 2].map(|axis| {
        let range = range_of(activations, axis);
        let (xs, ys): (Vec<f64>, Vec<f64>) = pairs(activations, axis)
            .map(|(t, b)| (normalise(range, t), b))
            .unzip();
        axis_polynomial(
            range,
            &solve(&xs, &ys, degree.min(MAX_POLYNOMIAL_COEFFICIENTS - 1)),
        )
    });
    PolynomialTables { settings, axes }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve_interpolates_and_fits() {
        // Through two points: a line.
        let c = solve(&[-1.0, 1.0], &[1.0, 3.0], 1);
        assert!((c[0] - 2.0).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12);
        // A cubic sampled densely is recovered.
        let xs: Vec<f64> = (0..201).map(|i| -1.0 + i as f64 * 0.01).collect();
        let ys: Vec<f64> = xs
            .iter()
            .map(|x| 0.5 - 0.2 * x + 0.1 * x * x + 0.05 * x * x * x)
            .collect();
        let c = solve(&xs, &ys, 3);
        for (got, want) in c.iter().zip([0.5, -0.2, 0.1, 0.05]) {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
    }
}
