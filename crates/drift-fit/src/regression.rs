//! Least squares, once for the whole calibration: the polynomial baselines, the switch-on rate's
//! parabola and the closed loop's terms all solve their normal equations here.

use nalgebra::{DMatrix, DVector};

/// Solves the normal equations `normal · b = rhs` by LU decomposition; `None` when they are
/// singular.
pub fn solve(normal: DMatrix<f64>, rhs: &DVector<f64>) -> Option<Vec<f64>> {
    normal.lu().solve(rhs).map(|b| b.iter().copied().collect())
}

/// Least squares `y ≈ X b` over the rows of `X`, via normal equations (for a handful of columns).
///
/// A row with a non-finite value (a sensor fault the corrector flagged) says nothing about the
/// fit, and one NaN would poison the whole solve: such rows are left out. A tiny ridge keeps
/// constant or collinear columns solvable; if the system is still singular, every coefficient is
/// 0. No rows (or no columns) give no coefficients.
pub fn least_squares(rows: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let k = rows.first().map_or(0, Vec::len);
    if k == 0 {
        return Vec::new();
    }
    let mut normal = DMatrix::<f64>::zeros(k, k);
    let mut rhs = DVector::<f64>::zeros(k);
    let finite = |row: &Vec<f64>, t: f64| t.is_finite() && row.iter().all(|v| v.is_finite());
    for (row, &t) in rows.iter().zip(y).filter(|(row, t)| finite(row, **t)) {
        for r in 0..k {
            rhs[r] += row[r] * t;
            for c in 0..k {
                normal[(r, c)] += row[r] * row[c];
            }
        }
    }
    for d in 0..k {
        normal[(d, d)] += 1e-12 * (1.0 + normal[(d, d)]);
    }
    solve(normal, &rhs).unwrap_or_else(|| vec![0.0; k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_leaves_out_non_finite_points() {
        // y = 2 + 3x, one NaN residual and one infinite candidate among them.
        let mut rows: Vec<Vec<f64>> = (0..10).map(|i| vec![1.0, f64::from(i)]).collect();
        let mut y: Vec<f64> = (0..10).map(|i| 2.0 + 3.0 * f64::from(i)).collect();
        y[3] = f64::NAN;
        rows[5][1] = f64::INFINITY;
        let b = least_squares(&rows, &y);
        assert!(
            (b[0] - 2.0).abs() < 1e-6 && (b[1] - 3.0).abs() < 1e-6,
            "{b:?}"
        );
        assert!(least_squares(&[], &[]).is_empty());
    }

    #[test]
    fn singular_equations_have_no_solution() {
        let normal = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(solve(normal, &DVector::from_column_slice(&[1.0, 2.0])).is_none());
        let normal = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 4.0]);
        assert_eq!(
            solve(normal, &DVector::from_column_slice(&[1.0, 2.0])),
            Some(vec![0.5, 0.5])
        );
    }
}
