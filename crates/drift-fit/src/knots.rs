//! Reference times "where the curves bend most": greedy largest-error knot insertion.
//!
//! Start with the first reference time (where the rise has become measurable) and the end of the
//! activation. Then, until there are `reference_count` knots, add the grid time where the table
//! would err most: the largest drift error `|k_table(t) − k(t)| · rise(t)` over every curve of
//! every set point, with `k_table` the piecewise-linear interpolation through the knots (held before
//! the first, as the corrector does). Measuring the error as drift rather than as `k` keeps the
//! noisy `k` of the first seconds (tiny rise) from attracting knots that buy no accuracy.

use crate::curves::SetPointCurves;

/// `k = g / rise` of one curve at grid point `i`, averaged over `window` points centred there (the
/// paper's `d_j`).
pub fn k_window(drift: &[f64], rise: &[f64], i: usize, window: usize) -> f64 {
    let lo = i.saturating_sub(window / 2);
    let hi = (lo + window.max(1)).min(drift.len());
    let (sum, count) = (lo..hi)
        .filter(|&j| rise[j].abs() > 1e-9)
        .fold((0.0, 0usize), |(s, c), j| (s + drift[j] / rise[j], c + 1));
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// Mean of `values` over the same window.
pub fn mean_window(values: &[f64], i: usize, window: usize) -> f64 {
    let lo = i.saturating_sub(window / 2);
    let hi = (lo + window.max(1)).min(values.len());
    values[lo..hi].iter().sum::<f64>() / (hi - lo).max(1) as f64
}

/// Chooses `count` reference grid indices for `axis` from the curves of every set point.
/// `first` is the first reference index; the last index is the end of the shortest curve.
pub fn choose(
    set_points: &[SetPointCurves],
    axis: usize,
    first: usize,
    count: usize,
    window: usize,
) -> Vec<usize> {
    let curves: Vec<(&[f64], &[f64])> = set_points
        .iter()
        .flat_map(|sp| sp.curves.iter())
        .map(|c| {
            (
                c.drift_dps[axis].as_slice(),
                c.rise_celsius[axis].as_slice(),
            )
        })
        .collect();
    let len = curves.iter().map(|(d, _)| d.len()).min().unwrap_or(0);
    if len <= first + 1 || count < 2 {
        return vec![first.min(len.saturating_sub(1))];
    }
    let last = len - 1;
    let mut knots = vec![first, last];
    // k of each curve at every grid point (pointwise ratio: the error target), and at knots (the
    // windowed mean the table stores).
    let pointwise: Vec<Vec<f64>> = curves
        .iter()
        .map(|(d, r)| {
            (0..len)
                .map(|i| if r[i].abs() > 1e-9 { d[i] / r[i] } else { 0.0 })
                .collect()
        })
        .collect();
    while knots.len() < count {
        let at_knots: Vec<Vec<f64>> = curves
            .iter()
            .map(|(d, r)| knots.iter().map(|&j| k_window(d, r, j, window)).collect())
            .collect();
        let mut worst = (0.0_f64, None);
        // Only after the first reference time: before it the table holds k by design.
        for i in first..len {
            if knots.contains(&i) {
                continue;
            }
            // Knot segment containing i.
            let seg = knots.windows(2).position(|w| w[0] <= i && i < w[1]);
            for (c, (_, r)) in curves.iter().enumerate() {
                let k_table = match seg {
                    None => at_knots[c][knots.len() - 1],
                    Some(s) => {
                        let (a, b) = (knots[s], knots[s + 1]);
                        let w = (i - a) as f64 / (b - a) as f64;
                        at_knots[c][s] + (at_knots[c][s + 1] - at_knots[c][s]) * w
                    }
                };
                let error = ((k_table - pointwise[c][i]) * r[i]).abs();
                if error > worst.0 {
                    worst = (error, Some(i));
                }
            }
        }
        match worst.1 {
            Some(i) => {
                knots.push(i);
                knots.sort_unstable();
            }
            None => break,
        }
    }
    knots
}
