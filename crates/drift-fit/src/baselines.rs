//! The baselines, fitted on the same calibration activations as the paper's tables: bias as a
//! polynomial of the sensor temperature, no heating dynamics. Absolute (`bias = p(T)`: the paper's
//! standard calibration, the PX4/ArduPilot least-squares polynomial) and relative to the switch-on
//! (`bias = q(T_on) + p(T) − p(T_on)`, orders up to the cubic chosen by cross-validation over
//! held-out temperature bands, or cubic as PX4 and ArduPilot fit theirs).

use std::collections::BTreeMap;

use drift_core::{
    PolynomialAxis, PolynomialTables, RelativePolynomialAxis, RelativePolynomialTables, Settings,
    MAX_POLYNOMIAL_COEFFICIENTS,
};
use nalgebra::{DMatrix, DVector};

use crate::analyse::Analysed;
use crate::parallel::per_axis;

/// The normalised variable `x = (T − mid) / half_span` over a temperature range.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Normalise {
    mid: f64,
    half: f64,
}

impl Normalise {
    pub(crate) fn over(range: [f64; 2]) -> Self {
        let half = 0.5 * (range[1] - range[0]);
        Self {
            mid: range[0] + half,
            half,
        }
    }

    #[inline]
    pub(crate) fn apply(self, t: f64) -> f64 {
        (t - self.mid) / self.half
    }
}

/// Temperature range (°C) of every grid point of `activations` on `axis`.
///
/// From each activation's smallest and largest rise: adding the switch-on temperature rounds
/// monotonically, so the extremes of `switch-on + rise` are those of the rise, and a min/max over
/// the f32 rises runs at memory speed.
pub(crate) fn range_of(activations: &[&Analysed], axis: usize) -> [f64; 2] {
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

pub(crate) fn axis_polynomial(range: [f64; 2], coefficients: &[f64]) -> PolynomialAxis {
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

/// Highest order the relative baseline tries for the drift polynomial `p`: the cubic PX4 and
/// ArduPilot use. Higher orders follow the calibrated ambients' bands and swing between them, where
/// a unit is used and no calibration point pins them.
pub const MAX_RELATIVE_DRIFT_DEGREE: usize = 3;
/// Highest order it tries for the turn-on polynomial `q`.
pub const MAX_TURN_ON_DEGREE: usize = 3;
/// Width of the temperature bands the relative baseline's cross-validation leaves out in turn, °C:
/// an order is judged on temperatures it was not fitted at, as a unit between its calibration set
/// points is.
pub const HELD_OUT_BAND_CELSIUS: f64 = 2.5;

/// Sums of a least-squares problem `y ≈ Σ_j c_j φ_j` over a group of points: `Σ φφᵀ`, `Σ φ y` and
/// `Σ y²`, enough for the fit on any union of groups and the squared error on any group, for
/// every leading subset of the basis (every lower order).
#[derive(Clone, Copy)]
pub(crate) struct Gram {
    phi_phi: [[f64; MAX_POLYNOMIAL_COEFFICIENTS]; MAX_POLYNOMIAL_COEFFICIENTS],
    phi_y: [f64; MAX_POLYNOMIAL_COEFFICIENTS],
    y_y: f64,
}

impl Default for Gram {
    fn default() -> Self {
        Self {
            phi_phi: [[0.0; MAX_POLYNOMIAL_COEFFICIENTS]; MAX_POLYNOMIAL_COEFFICIENTS],
            phi_y: [0.0; MAX_POLYNOMIAL_COEFFICIENTS],
            y_y: 0.0,
        }
    }
}

impl Gram {
    pub(crate) fn add(&mut self, phi: &[f64], y: f64) {
        for (r, &a) in phi.iter().enumerate() {
            for (c, &b) in phi.iter().enumerate().skip(r) {
                self.phi_phi[r][c] += a * b;
            }
            self.phi_y[r] += a * y;
        }
        self.y_y += y * y;
    }

    fn plus(mut self, other: &Gram, sign: f64) -> Gram {
        for (row, other_row) in self.phi_phi.iter_mut().zip(&other.phi_phi) {
            for (v, o) in row.iter_mut().zip(other_row) {
                *v += sign * o;
            }
        }
        for (v, o) in self.phi_y.iter_mut().zip(&other.phi_y) {
            *v += sign * o;
        }
        self.y_y += sign * other.y_y;
        self
    }

    /// The least-squares coefficients of the first `columns` basis functions (None if singular).
    fn solve(&self, columns: usize) -> Option<Vec<f64>> {
        let normal =
            DMatrix::<f64>::from_fn(columns, columns, |r, c| self.phi_phi[r.min(c)][r.max(c)]);
        let rhs = DVector::<f64>::from_column_slice(&self.phi_y[..columns]);
        crate::regression::solve(normal, &rhs).filter(|c| c.iter().all(|v| v.is_finite()))
    }

    /// Σ (y − φ·c)² over this group's points for coefficients `c` of the leading basis.
    fn squared_error(&self, c: &[f64]) -> f64 {
        let mut error = self.y_y;
        for (r, &a) in c.iter().enumerate() {
            error -= 2.0 * a * self.phi_y[r];
            for (k, &b) in c.iter().enumerate() {
                error += a * b * self.phi_phi[r.min(k)][r.max(k)];
            }
        }
        error
    }
}

/// The order (number of leading basis functions, from `min_columns` to `max_columns`) whose fit
/// on all groups but one predicts the left-out one best, summed over every group left out in
/// turn; and its coefficients fitted on every group. One group only: the lowest order.
pub(crate) fn cross_validated(
    groups: &[Gram],
    min_columns: usize,
    max_columns: usize,
) -> Option<(usize, Vec<f64>)> {
    let total = groups
        .iter()
        .fold(Gram::default(), |sum, g| sum.plus(g, 1.0));
    let mut best: Option<(f64, usize)> = None;
    if groups.len() >= 2 {
        for columns in min_columns..=max_columns {
            let mut error = 0.0;
            for group in groups {
                match total.plus(group, -1.0).solve(columns) {
                    Some(c) => error += group.squared_error(&c),
                    None => {
                        error = f64::INFINITY;
                        break;
                    }
                }
            }
            if error.is_finite() && best.is_none_or(|(e, _)| error < e) {
                best = Some((error, columns));
            }
        }
    }
    let columns = best.map_or(min_columns, |(_, c)| c);
    total.solve(columns).map(|c| (columns, c))
}

/// The temperature band (°C, [`HELD_OUT_BAND_CELSIUS`] wide) the cross-validation leaves out
/// whole: a fit without it has no point there and must interpolate (or extrapolate, for the end
/// bands) across it, as it must between calibration set points in use.
pub(crate) fn band_key(celsius: f64) -> i64 {
    (celsius / HELD_OUT_BAND_CELSIUS).floor() as i64
}

/// The orders the relative baseline chose, per axis: `p`'s and `q`'s degree.
pub type RelativeOrders = [(usize, usize); 3];

/// How the relative baseline's orders are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Orders {
    /// Cross-validated over held-out temperature bands, up to the caps.
    HeldOutBands,
    /// Cubic `p` and `q`, as PX4 and ArduPilot fit theirs.
    Cubic,
}

/// The baseline relative to the switch-on: per axis, `p` by least squares on every calibration
/// grid point's drift since switch-on (`g = p(T) − p(T_on)`, the basis `x^k − x_on^k`, k ≥ 1),
/// and `q` by least squares on each activation's initial bias against its switch-on temperature;
/// each order chosen by cross-validation that leaves out one temperature band at a time
/// ([`HELD_OUT_BAND_CELSIUS`]; `p` by the grid point's temperature, `q` by the switch-on
/// temperature), up to the cubic ([`MAX_RELATIVE_DRIFT_DEGREE`], [`MAX_TURN_ON_DEGREE`]).
///
/// Why bands, not series: a series covers the temperatures every other series of its set point
/// covers, so leaving one out never asks an order to predict a temperature it was not fitted at;
/// a band does, which is what a unit used between its calibration set points asks.
pub fn relative_polynomial(
    activations: &[&Analysed],
    settings: Settings,
) -> (RelativePolynomialTables, RelativeOrders) {
    relative_with(activations, settings, Orders::HeldOutBands)
}

/// The cubic relative to the switch-on: [`relative_polynomial`]'s form with `p` and `q` cubic, no
/// order chosen (the cubic PX4 and ArduPilot fit, taken relative to the switch-on).
pub fn relative_cubic(activations: &[&Analysed], settings: Settings) -> RelativePolynomialTables {
    relative_with(activations, settings, Orders::Cubic).0
}

fn relative_with(
    activations: &[&Analysed],
    settings: Settings,
    orders: Orders,
) -> (RelativePolynomialTables, RelativeOrders) {
    let fitted = per_axis(|axis| {
        let range = range_of(activations, axis);
        let normalise = Normalise::over(range);
        let mut drift_groups: BTreeMap<i64, Gram> = BTreeMap::new();
        let mut turn_on_groups: BTreeMap<i64, Gram> = BTreeMap::new();
        let mut phi = [0.0; MAX_RELATIVE_DRIFT_DEGREE + 1];
        for a in activations {
            let on = a.switch_on_celsius[axis];
            let x_on = normalise.apply(on);
            for (&rise, &g) in a.rise_celsius[axis].iter().zip(&a.drift_dps[axis]) {
                let celsius = on + f64::from(rise);
                let (x, g) = (normalise.apply(celsius), f64::from(g));
                if !(x.is_finite() && g.is_finite()) {
                    continue;
                }
                let (mut power, mut power_on) = (1.0, 1.0);
                for value in phi.iter_mut().take(MAX_RELATIVE_DRIFT_DEGREE) {
                    power *= x;
                    power_on *= x_on;
                    *value = power - power_on;
                }
                drift_groups
                    .entry(band_key(celsius))
                    .or_default()
                    .add(&phi[..MAX_RELATIVE_DRIFT_DEGREE], g);
            }
            let bias = a.initial_bias_dps[axis];
            if x_on.is_finite() && bias.is_finite() {
                let mut power = 1.0;
                for value in phi.iter_mut().take(MAX_TURN_ON_DEGREE + 1) {
                    *value = power;
                    power *= x_on;
                }
                turn_on_groups
                    .entry(band_key(on))
                    .or_default()
                    .add(&phi[..=MAX_TURN_ON_DEGREE], bias);
            }
        }
        let drift_groups: Vec<Gram> = drift_groups.into_values().collect();
        let turn_on_groups: Vec<Gram> = turn_on_groups.into_values().collect();
        let (drift_min, turn_on_min) = match orders {
            Orders::HeldOutBands => (1, 1),
            Orders::Cubic => (MAX_RELATIVE_DRIFT_DEGREE, MAX_TURN_ON_DEGREE + 1),
        };
        let (drift_columns, drift) =
            cross_validated(&drift_groups, drift_min, MAX_RELATIVE_DRIFT_DEGREE)
                .unwrap_or((1, vec![0.0]));
        let (turn_on_columns, turn_on) =
            cross_validated(&turn_on_groups, turn_on_min, MAX_TURN_ON_DEGREE + 1)
                .unwrap_or((1, vec![0.0]));
        // p's constant term cancels in p(T) − p(T_on): stored as 0.
        let mut p = vec![0.0];
        p.extend(drift);
        (
            RelativePolynomialAxis {
                drift: axis_polynomial(range, &p),
                turn_on: axis_polynomial(range, &turn_on),
            },
            (drift_columns, turn_on_columns - 1),
        )
    });
    let [(x, ox), (y, oy), (z, oz)] = fitted;
    (
        RelativePolynomialTables {
            settings,
            axes: [x, y, z],
        },
        [ox, oy, oz],
    )
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

    /// The drift's temperature law of the activations below: drift since switch-on
    /// `truth(T) − truth(T_on)`.
    fn truth(t: f64) -> f64 {
        0.002 * (t - 30.0) + 0.0001 * (t - 30.0).powi(2)
    }

    /// Activations whose drift since switch-on follows [`truth`],
    /// turned on with a bias of `0.01·(T_on − 30)` plus ±0.004 of turn-on jitter.
    fn activations() -> Vec<Analysed> {
        let mut out = Vec::new();
        for (s, set_point) in [30.0, 40.0].into_iter().enumerate() {
            for series in 1..=3u32 {
                for activation in 1..=3u32 {
                    let on = set_point + f64::from(activation - 1) * 1.5;
                    let jitter = if (series + activation) % 2 == 0 {
                        0.004
                    } else {
                        -0.004
                    };
                    let rise: Vec<f32> = (0..200).map(|i| i as f32 * 0.025).collect();
                    let drift: Vec<f32> = rise
                        .iter()
                        .map(|&r| (truth(on + f64::from(r)) - truth(on)) as f32)
                        .collect();
                    out.push(Analysed {
                        labels: drift_recording::SegmentLabels {
                            unit_id: "U".into(),
                            set_point_celsius: set_point,
                            session_set_point_celsius: None,
                            series_kind: drift_recording::SeriesKind::Protocol,
                            series: series + 10 * s as u32,
                            repeat: 1,
                            activation,
                            interval_min: Some(5.0),
                            off_before_s: Some(300.0),
                        },
                        grid_ms: 10,
                        sample_rate_hz: 1000,
                        switch_on_raw: [(on * 200.0) as f32; 3],
                        switch_on_celsius: [on; 3],
                        initial_bias_dps: [0.01 * (on - 30.0) + jitter; 3],
                        drift_dps: [drift.clone(), drift.clone(), drift],
                        rise_celsius: [rise.clone(), rise.clone(), rise],
                        temperature_scale: Default::default(),
                    });
                }
            }
        }
        out
    }

    /// The relative form recovers the drift after switch-on and the turn-on bias's trend through
    /// the jitter; the absolute least-squares polynomial, fitted on the same points, bends its
    /// drift to the turn-on biases of the ambients.
    #[test]
    fn the_relative_baseline_fits_the_drift_since_switch_on_not_the_turn_on_bias() {
        let data = activations();
        let refs: Vec<&Analysed> = data.iter().collect();
        let (relative, orders) = relative_polynomial(&refs, Settings::default());
        assert!(orders[0].0 >= 2, "{orders:?}");
        let axis = &relative.axes[0];
        let settings = Settings::default();
        let mut state = Default::default();
        use drift_core::AxisModel;
        let (bias, _) = axis.power_on(&settings, 35.0, &mut state);
        assert!((bias - 0.05).abs() < 0.002, "turn-on bias {bias}");
        let (drift, _) = axis.drift(&settings, &mut state, 0, 38.0, 3.0);
        let want = (truth(38.0) - truth(35.0)) as f32;
        assert!((drift - want).abs() < 2e-4, "drift {drift} vs {want}");
        // The absolute cubic on the same activations: its slope is the ambients' turn-on trend.
        let absolute = least_squares_polynomial(&refs, 3, settings);
        let mut state = Default::default();
        let (at_on, _) = absolute.axes[0].power_on(&settings, 35.0, &mut state);
        let (drift_abs, _) = absolute.axes[0].drift(&settings, &mut state, 0, 38.0, 3.0);
        assert!(
            (drift_abs - want).abs() > 5.0 * (drift - want).abs(),
            "absolute {drift_abs} (at switch-on {at_on}), relative {drift}, truth {want}"
        );
    }
}
