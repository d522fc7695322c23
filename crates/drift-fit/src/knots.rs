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

/// The largest drift error strictly between knots `a` and `b` (`k_a`, `k_b`: the knots' `k` per
/// curve) over every curve, and the first grid index where it occurs; `(0.0, None)` when no error
/// is positive.
///
/// Curve by curve (contiguous and vectorisable) into a per-index maximum, then the first index of
/// the largest: the same answer as scanning index by index and curve by curve, because only the
/// largest error and the first index reaching it matter, not which curve reached it.
fn worst_between(
    pointwise: &[Vec<f64>],
    rises: &[&[f64]],
    (a, b): (usize, usize),
    (k_a, k_b): (&[f64], &[f64]),
    scratch: &mut Vec<f64>,
) -> (f64, Option<usize>) {
    if b <= a + 1 {
        return (0.0, None);
    }
    let weights: Vec<f64> = (a + 1..b)
        .map(|i| (i - a) as f64 / (b - a) as f64)
        .collect();
    scratch.clear();
    scratch.resize(weights.len(), 0.0);
    for (c, (k, rise)) in pointwise.iter().zip(rises).enumerate() {
        let (lo, hi) = (k_a[c], k_b[c]);
        let inside = (k[a + 1..b].iter().zip(&rise[a + 1..b])).zip(&weights);
        for (largest, ((&k, &rise), &w)) in scratch.iter_mut().zip(inside) {
            let k_table = lo + (hi - lo) * w;
            let error = ((k_table - k) * rise).abs();
            if error > *largest {
                *largest = error;
            }
        }
    }
    let mut worst = (0.0, None);
    for (offset, &error) in scratch.iter().enumerate() {
        if error > worst.0 {
            worst = (error, Some(a + 1 + offset));
        }
    }
    worst
}

/// Chooses `count` reference grid indices for `axis` from the curves of every set point.
/// `first` is the first reference index; the last index is the end of the shortest curve.
///
/// A new knot changes the table only between its two neighbours, so the largest error of every
/// other knot segment is kept from the previous round and only the split segment is scanned again:
/// one scan of the grid in all, instead of one per knot added.
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
    let rises: Vec<&[f64]> = curves.iter().map(|&(_, r)| r).collect();
    let k_at = |j: usize| -> Vec<f64> {
        curves
            .iter()
            .map(|(d, r)| k_window(d, r, j, window))
            .collect()
    };
    let mut scratch = Vec::new();
    let mut knots = vec![first, last];
    let mut k_knots = vec![k_at(first), k_at(last)];
    // Largest error and where, per knot segment (between knots[s] and knots[s + 1]). Before the
    // first reference time the table holds k by design, so only what follows it is scanned.
    let mut segments = vec![worst_between(
        &pointwise,
        &rises,
        (first, last),
        (&k_knots[0], &k_knots[1]),
        &mut scratch,
    )];
    while knots.len() < count {
        // The first segment with the largest error holds the first grid index with it.
        let mut worst = (0.0_f64, None);
        for (s, &(error, at)) in segments.iter().enumerate() {
            if let Some(i) = at {
                if error > worst.0 {
                    worst = (error, Some((s, i)));
                }
            }
        }
        let Some((s, i)) = worst.1 else { break };
        knots.insert(s + 1, i);
        k_knots.insert(s + 1, k_at(i));
        let mut scan = |s: usize| {
            worst_between(
                &pointwise,
                &rises,
                (knots[s], knots[s + 1]),
                (&k_knots[s], &k_knots[s + 1]),
                &mut scratch,
            )
        };
        let (left, right) = (scan(s), scan(s + 1));
        segments[s] = left;
        segments.insert(s + 1, right);
    }
    knots
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curves::{AveragedCurve, CurveKey};
    use proptest::prelude::*;

    /// The definition: every round, every grid index after the first knot, every curve.
    fn choose_by_full_scan(
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
        let mut knots = vec![first, len - 1];
        while knots.len() < count {
            let at_knots: Vec<Vec<f64>> = curves
                .iter()
                .map(|(d, r)| knots.iter().map(|&j| k_window(d, r, j, window)).collect())
                .collect();
            let mut worst = (0.0_f64, None);
            for i in first..len {
                if knots.contains(&i) {
                    continue;
                }
                let seg = knots.windows(2).position(|w| w[0] <= i && i < w[1]);
                for (c, (d, r)) in curves.iter().enumerate() {
                    let pointwise = if r[i].abs() > 1e-9 { d[i] / r[i] } else { 0.0 };
                    let k_table = match seg {
                        None => at_knots[c][knots.len() - 1],
                        Some(s) => {
                            let (a, b) = (knots[s], knots[s + 1]);
                            let w = (i - a) as f64 / (b - a) as f64;
                            at_knots[c][s] + (at_knots[c][s + 1] - at_knots[c][s]) * w
                        }
                    };
                    let error = ((k_table - pointwise) * r[i]).abs();
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

    fn set_point(curves: Vec<(Vec<f64>, Vec<f64>)>) -> SetPointCurves {
        SetPointCurves {
            set_point_celsius: 30.0,
            grid_ms: 10,
            ambient_celsius: [30.0; 3],
            initial_bias_dps: [0.0; 3],
            curves: curves
                .into_iter()
                .map(|(drift, rise)| AveragedCurve {
                    key: CurveKey::Independent,
                    members: 1,
                    drift_dps: [drift.clone(), drift.clone(), drift],
                    rise_celsius: [rise.clone(), rise.clone(), rise],
                    switch_on_celsius: [30.0; 3],
                    initial_bias_dps: [0.0; 3],
                })
                .collect(),
        }
    }

    /// Curves of `len` points, coarsely quantised and mostly without drift, so that equal errors
    /// (ties) are common, with an occasional zero rise and NaN drift.
    fn curves(len: usize) -> impl Strategy<Value = Vec<(Vec<f64>, Vec<f64>)>> {
        let point = (0_i32..3, 1_i32..4, 0_u8..40).prop_map(|(d, r, kind)| match kind {
            0 => (f64::NAN, f64::from(r)),
            1 => (f64::from(d), 0.0),
            2..=9 => (f64::from(d), f64::from(r)),
            _ => (0.0, f64::from(r)),
        });
        prop::collection::vec(prop::collection::vec(point, len..len + 20), 1..5).prop_map(|c| {
            c.into_iter()
                .map(|points| points.into_iter().unzip())
                .collect()
        })
    }

    proptest! {
        #[test]
        fn keeping_the_other_segments_errors_chooses_what_the_full_scan_chooses(
            sets in prop::collection::vec(curves(40), 1..3),
            first in 0_usize..10,
            count in 1_usize..12,
            window in 0_usize..6,
        ) {
            let set_points: Vec<SetPointCurves> = sets.into_iter().map(set_point).collect();
            prop_assert_eq!(
                choose(&set_points, 1, first, count, window),
                choose_by_full_scan(&set_points, 1, first, count, window)
            );
        }
    }

    #[test]
    fn smooth_curves_get_their_knots_where_they_bend() {
        let len = 3000;
        let curve = |scale: f64| -> (Vec<f64>, Vec<f64>) {
            let rise: Vec<f64> = (0..len)
                .map(|i| 5.0 * (1.0 - (-(i as f64) / 400.0).exp()))
                .collect();
            let drift = rise
                .iter()
                .enumerate()
                .map(|(i, r)| scale * r * (1.0 + (-(i as f64) / 150.0).exp()))
                .collect();
            (drift, rise)
        };
        let set_points = vec![
            set_point(vec![curve(0.004), curve(0.003)]),
            set_point(vec![curve(-0.002), curve(0.001)]),
        ];
        let knots = choose(&set_points, 0, 200, 8, 10);
        assert_eq!(knots, choose_by_full_scan(&set_points, 0, 200, 8, 10));
        assert_eq!(knots.len(), 8);
        assert!(knots.windows(2).all(|w| w[0] < w[1]));
    }
}
