//! The two baselines, fitted on the same calibration activations as the paper's tables: bias as a
//! polynomial of the absolute sensor temperature, no heating dynamics.

use drift_core::{PolynomialAxis, PolynomialTables, Settings, MAX_POLYNOMIAL_COEFFICIENTS};
use nalgebra::{DMatrix, DVector};

use crate::analyse::Analysed;
use crate::parallel::per_axis;

/// The normalised variable `x = (T − mid) / half_span` over a temperature range.
#[derive(Debug, Clone, Copy)]
struct Normalise {
    mid: f64,
    half: f64,
}

impl Normalise {
    fn over(range: [f64; 2]) -> Self {
        let half = 0.5 * (range[1] - range[0]);
        Self {
            mid: range[0] + half,
            half,
        }
    }

    #[inline]
    fn apply(self, t: f64) -> f64 {
        (t - self.mid) / self.half
    }
}

/// Temperature range (°C) of every grid point of `activations` on `axis`.
///
/// From each activation's smallest and largest rise: adding the switch-on temperature rounds
/// monotonically, so the extremes of `switch-on + rise` are those of the rise, and a min/max over
/// the f32 rises runs at memory speed.
fn range_of(activations: &[&Analysed], axis: usize) -> [f64; 2] {
    let (lo, hi) = activations
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
            let (rise_lo, rise_hi) = a.rise_celsius[axis]
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &r| {
                    (lo.min(r), hi.max(r))
                });
            let on = a.switch_on_celsius[axis];
            (
                lo.min(on + f64::from(rise_lo)),
                hi.max(on + f64::from(rise_hi)),
            )
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

/// The normal equations of a least-squares polynomial in the normalised variable, accumulated
/// point by point: O(n · degree), no n × degree matrix and no list of points in memory.
///
/// Entry (r, c) of the normal matrix is the sum of x^(r+c), so the 2·columns power sums are
/// accumulated once, in the data's order (the same additions an entry-by-entry accumulation would
/// make).
struct NormalEquations {
    columns: usize,
    power_sums: [f64; 2 * MAX_POLYNOMIAL_COEFFICIENTS],
    rhs: [f64; MAX_POLYNOMIAL_COEFFICIENTS],
    /// Σ y from −0.0 (as `Iterator::sum`), for the mean when the system is singular.
    y_sum: f64,
    count: usize,
}

impl NormalEquations {
    /// `degree` ≤ 7 (the image's capacity).
    fn new(degree: usize) -> Self {
        Self {
            columns: (degree + 1).min(MAX_POLYNOMIAL_COEFFICIENTS),
            power_sums: [0.0; 2 * MAX_POLYNOMIAL_COEFFICIENTS],
            rhs: [0.0; MAX_POLYNOMIAL_COEFFICIENTS],
            y_sum: -0.0,
            count: 0,
        }
    }

    /// Adds `(x, y)` points, in order.
    fn add(&mut self, points: impl Iterator<Item = (f64, f64)>) {
        // The degree as a constant, so the loop over powers unrolls and the sums stay in registers.
        match self.columns {
            1 => self.add_with::<1>(points),
            2 => self.add_with::<2>(points),
            3 => self.add_with::<3>(points),
            4 => self.add_with::<4>(points),
            5 => self.add_with::<5>(points),
            6 => self.add_with::<6>(points),
            7 => self.add_with::<7>(points),
            _ => self.add_with::<8>(points),
        }
    }

    #[inline(always)]
    fn add_with<const COLUMNS: usize>(&mut self, points: impl Iterator<Item = (f64, f64)>) {
        let (mut sums, mut rhs, mut y_sum) = (self.power_sums, self.rhs, self.y_sum);
        let mut count = 0;
        for (x, y) in points {
            let mut p = 1.0;
            for (k, sum) in sums.iter_mut().take(2 * COLUMNS).enumerate() {
                if k < COLUMNS {
                    rhs[k] += p * y;
                }
                *sum += p;
                p *= x;
            }
            y_sum += y;
            count += 1;
        }
        (self.power_sums, self.rhs, self.y_sum) = (sums, rhs, y_sum);
        self.count += count;
    }

    /// The coefficients (by LU), or the mean of y alone if the system is singular.
    fn solve(&self) -> Vec<f64> {
        let columns = self.columns;
        let normal = DMatrix::<f64>::from_fn(columns, columns, |r, c| self.power_sums[r + c]);
        let rhs = DVector::<f64>::from_column_slice(&self.rhs[..columns]);
        crate::regression::solve(normal, &rhs)
            .unwrap_or_else(|| vec![self.y_sum / self.count.max(1) as f64])
    }
}

/// Solves the (small) least-squares or interpolation system `V c = y` in the normalised variable.
fn solve(xs: &[f64], ys: &[f64], degree: usize) -> Vec<f64> {
    let mut equations = NormalEquations::new(degree);
    equations.add(xs.iter().copied().zip(ys.iter().copied()));
    equations.solve()
}

/// The paper's "standard" calibration: per set point one calibration point (mean sensor temperature,
/// mean bias over its activations), and the Lagrange polynomial through them (degree = points − 1).
pub fn standard(by_set_point: &[Vec<&Analysed>], settings: Settings) -> PolynomialTables {
    let axes = per_axis(|axis| {
        let all: Vec<&Analysed> = by_set_point.iter().flatten().copied().collect();
        let range = range_of(&all, axis);
        let points: Vec<(f64, f64)> = by_set_point
            .iter()
            .filter(|group| !group.is_empty())
            .map(|group| {
                // Sums of temperature and bias over every grid point, in order.
                let (mut n, mut t, mut b) = (0.0, 0.0, 0.0);
                for a in group {
                    let (on, bias0) = (a.switch_on_celsius[axis], a.initial_bias_dps[axis]);
                    for (&rise, &drift) in a.rise_celsius[axis].iter().zip(&a.drift_dps[axis]) {
                        n += 1.0;
                        t += on + f64::from(rise);
                        b += bias0 + f64::from(drift);
                    }
                }
                (t / n, b / n)
            })
            .collect();
        let normalise = Normalise::over(range);
        let xs: Vec<f64> = points.iter().map(|p| normalise.apply(p.0)).collect();
        let ys: Vec<f64> = points.iter().map(|p| p.1).collect();
        // Through every point: as many coefficients as points (capped at the image's capacity).
        let degree = points.len().clamp(1, MAX_POLYNOMIAL_COEFFICIENTS) - 1;
        axis_polynomial(range, &solve(&xs, &ys, degree))
    });
    PolynomialTables { settings, axes }
}

/// The PX4/ArduPilot practice: a least-squares polynomial of the given degree per axis over every
/// calibration grid point.
pub fn least_squares_polynomial(
    activations: &[&Analysed],
    degree: usize,
    settings: Settings,
) -> PolynomialTables {
    let axes = per_axis(|axis| {
        let range = range_of(activations, axis);
        let normalise = Normalise::over(range);
        let mut equations = NormalEquations::new(degree.min(MAX_POLYNOMIAL_COEFFICIENTS - 1));
        for a in activations {
            let (on, bias0) = (a.switch_on_celsius[axis], a.initial_bias_dps[axis]);
            equations.add(a.rise_celsius[axis].iter().zip(&a.drift_dps[axis]).map(
                |(&rise, &drift)| {
                    (
                        normalise.apply(on + f64::from(rise)),
                        bias0 + f64::from(drift),
                    )
                },
            ));
        }
        axis_polynomial(range, &equations.solve())
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
