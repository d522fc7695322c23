//! Eigen-decomposition of a small symmetric matrix, by nalgebra's `SymmetricEigen` (symmetric QR
//! with implicit shifts): well-kept, accurate to rounding, and no hand-written numerics to maintain.

use nalgebra::{DMatrix, SymmetricEigen};

/// Eigenvalues and orthonormal eigenvectors of a symmetric `n × n` matrix (row-major).
///
/// Returns `(values, vectors)` where column `k` of `vectors` (row-major `n × n`) is the
/// eigenvector of `values[k]`.
pub(crate) fn symmetric_eigen(matrix: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    debug_assert_eq!(matrix.len(), n * n);
    let decomposition = SymmetricEigen::new(DMatrix::from_row_slice(n, n, matrix));
    let values = decomposition.eigenvalues.iter().copied().collect();
    let vectors = (0..n * n)
        .map(|k| decomposition.eigenvectors[(k / n, k % n)])
        .collect();
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reconstructs_a_symmetric_matrix() {
        let n = 4;
        let m = [
            4.0, 1.0, 0.5, 0.0, //
            1.0, 3.0, 0.2, 0.1, //
            0.5, 0.2, 2.0, 0.3, //
            0.0, 0.1, 0.3, 1.0,
        ];
        let (values, vectors) = symmetric_eigen(&m, n);
        for i in 0..n {
            for j in 0..n {
                let rebuilt: f64 = (0..n)
                    .map(|k| vectors[i * n + k] * values[k] * vectors[j * n + k])
                    .sum();
                assert!((rebuilt - m[i * n + j]).abs() < 1e-12, "({i},{j})");
            }
        }
        // Trace is preserved.
        let trace: f64 = values.iter().sum();
        assert!((trace - 10.0).abs() < 1e-12);
    }
}
