//! A candidate's gain over the baseline, cross-validated by series, from per-activation Gram
//! blocks.
//!
//! The diagnosis asks of every candidate how much of the residual it explains *beyond* what the
//! baseline (the paper model's known gaps and the bench's context channels) already explains, on
//! activations the fit did not see. For least squares everything that needs is in each
//! activation's Gram matrix of `[1, baseline…, candidate, residual]`: summed over the training
//! activations it gives the coefficients, and with a held-out activation's own block it gives the
//! held-out squared error. The samples are read once per activation, the folds and shuffles work
//! on the small blocks.

use nalgebra::{DMatrix, DVector};

/// One activation's points as the augmented Gram matrix of `[1, baseline…, candidate, residual]`
/// over its rows where every column is finite: entry (0, 0) counts the rows, row 0 holds the
/// columns' sums, the rest their cross products.
#[derive(Debug, Clone, PartialEq)]
pub struct Block(pub DMatrix<f64>);

impl Block {
    /// The block of `columns` (baseline columns, then the candidate, then the residual) over their
    /// common length.
    pub fn of(columns: &[&[f64]]) -> Self {
        let m = columns.len() + 1;
        let rows = columns.iter().map(|c| c.len()).min().unwrap_or(0);
        // The upper triangle, row by row, in one flat buffer.
        let mut upper = vec![0.0; m * (m + 1) / 2];
        let mut row = vec![1.0; m];
        for r in 0..rows {
            let mut finite = true;
            for (value, column) in row.iter_mut().skip(1).zip(columns) {
                *value = column[r];
                finite &= value.is_finite();
            }
            if !finite {
                continue;
            }
            let mut k = 0;
            for (i, &a) in row.iter().enumerate() {
                for &b in &row[i..] {
                    upper[k] += a * b;
                    k += 1;
                }
            }
        }
        let mut gram = DMatrix::zeros(m, m);
        let mut k = 0;
        for i in 0..m {
            for j in i..m {
                gram[(i, j)] = upper[k];
                gram[(j, i)] = upper[k];
                k += 1;
            }
        }
        Self(gram)
    }

    /// Points counted.
    pub fn rows(&self) -> f64 {
        self.0[(0, 0)]
    }

    /// The same points less their own means: what a shape within the activation is scored on.
    pub fn centred(&self) -> Self {
        let n = self.rows();
        let m = self.0.nrows();
        let mut out = DMatrix::zeros(m, m);
        if n <= 0.0 {
            return Self(out);
        }
        out[(0, 0)] = n;
        for i in 1..m {
            for j in 1..m {
                out[(i, j)] = self.0[(i, j)] - self.0[(0, i)] * self.0[(0, j)] / n;
            }
        }
        Self(out)
    }

    /// The activation as one point, its means: what an offset between activations is scored on.
    pub fn means(&self) -> Self {
        let n = self.rows();
        let m = self.0.nrows();
        if n <= 0.0 {
            return Self(DMatrix::zeros(m, m));
        }
        let v = DVector::from_iterator(m, (0..m).map(|i| self.0[(0, i)] / n));
        Self(&v * v.transpose())
    }
}

/// The least-squares coefficients of the last column on `regressors` (indices into the block),
/// from a training block; `None` when the system has no solution worth the name.
fn coefficients(train: &DMatrix<f64>, regressors: &[usize]) -> Option<DVector<f64>> {
    let y = train.nrows() - 1;
    let k = regressors.len();
    let a = DMatrix::from_fn(k, k, |i, j| train[(regressors[i], regressors[j])]);
    let b = DVector::from_fn(k, |i, _| train[(regressors[i], y)]);
    // Columns differ in scale by orders of magnitude (a channel × rise against a residual in
    // °/s): solve the equilibrated system.
    let scale = DVector::from_fn(k, |i, _| {
        let d = a[(i, i)];
        if d > 0.0 {
            1.0 / d.sqrt()
        } else {
            0.0
        }
    });
    let scaled = DMatrix::from_fn(k, k, |i, j| a[(i, j)] * scale[i] * scale[j]);
    let rhs = b.component_mul(&scale);
    let solved = match scaled.clone().cholesky() {
        Some(c) => c.solve(&rhs),
        None => scaled.pseudo_inverse(1e-10).ok()? * rhs,
    };
    let beta = solved.component_mul(&scale);
    beta.iter().all(|v| v.is_finite()).then_some(beta)
}

/// Squared error of the last column predicted by `beta` on `regressors` over a block's points.
fn squared_error(block: &DMatrix<f64>, regressors: &[usize], beta: &DVector<f64>) -> f64 {
    let y = block.nrows() - 1;
    let mut sse = block[(y, y)];
    for (i, &ri) in regressors.iter().enumerate() {
        sse -= 2.0 * beta[i] * block[(ri, y)];
        for (j, &rj) in regressors.iter().enumerate() {
            sse += beta[i] * beta[j] * block[(ri, rj)];
        }
    }
    sse.max(0.0)
}

/// What cross-validation of one level's blocks gives: the held-out squared error with the
/// baseline alone and with the candidate too, the residual's total sum of squares about its mean,
/// and whether every fold's candidate coefficient had the same sign.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossValidated {
    /// Held-out squared error, baseline alone.
    pub baseline_sse: f64,
    /// Held-out squared error, baseline and candidate.
    pub with_candidate_sse: f64,
    /// The residual's sum of squares about its mean over every block.
    pub total: f64,
    /// Every fold's candidate coefficient has the same sign.
    pub stable: bool,
}

impl CrossValidated {
    /// Share of the residual's variance the baseline explains out of sample.
    pub fn baseline_share(&self) -> f64 {
        if self.total > 0.0 {
            (1.0 - self.baseline_sse / self.total).max(0.0)
        } else {
            0.0
        }
    }

    /// Share of the residual's variance the candidate explains out of sample beyond the baseline;
    /// 0 when the folds disagree on its sign.
    pub fn gain(&self) -> f64 {
        // A baseline that predicts held-out data worse than their mean is credited as the mean:
        // without baseline columns the gain is then the plain cross-validated share.
        if self.total > 0.0 && self.stable {
            ((self.baseline_sse.min(self.total) - self.with_candidate_sse) / self.total).max(0.0)
        } else {
            0.0
        }
    }
}

/// Cross-validates blocks of `[1, baseline (k columns), candidate, residual]` with `fold_of[i]`
/// the fold block `i` is held out in. `baseline_sse` per fold may be given (it does not depend on
/// the candidate, so shuffles reuse it); otherwise it is computed.
pub fn cross_validate(
    blocks: &[Block],
    fold_of: &[usize],
    folds: usize,
    baseline_sse: Option<f64>,
) -> CrossValidated {
    let Some(first) = blocks.first() else {
        return CrossValidated {
            baseline_sse: 0.0,
            with_candidate_sse: 0.0,
            total: 0.0,
            stable: false,
        };
    };
    let m = first.0.nrows();
    let candidate = m - 2;
    let baseline: Vec<usize> = (0..candidate).collect();
    let full: Vec<usize> = (0..=candidate).collect();
    let mut all = DMatrix::zeros(m, m);
    for b in blocks {
        all += &b.0;
    }
    let n = all[(0, 0)];
    let y = m - 1;
    let total = if n > 0.0 {
        all[(y, y)] - all[(0, y)] * all[(0, y)] / n
    } else {
        0.0
    };
    let (mut base_sse, mut full_sse, mut positive, mut negative) = (0.0, 0.0, false, false);
    for fold in 0..folds {
        let mut train = DMatrix::zeros(m, m);
        let mut held = DMatrix::zeros(m, m);
        for (b, &f) in blocks.iter().zip(fold_of) {
            if f == fold {
                held += &b.0;
            } else {
                train += &b.0;
            }
        }
        if train[(0, 0)] < 2.0 || held[(0, 0)] <= 0.0 {
            continue;
        }
        if baseline_sse.is_none() {
            if let Some(beta) = coefficients(&train, &baseline) {
                base_sse += squared_error(&held, &baseline, &beta);
            }
        }
        if let Some(beta) = coefficients(&train, &full) {
            let c = beta[candidate];
            positive |= c > 0.0;
            negative |= c < 0.0;
            full_sse += squared_error(&held, &full, &beta);
        }
    }
    CrossValidated {
        baseline_sse: baseline_sse.unwrap_or(base_sse),
        with_candidate_sse: full_sse,
        total,
        stable: !(positive && negative),
    }
}

/// The baseline's coefficients (intercept left out) fitted on every block together: blocks of
/// `[1, baseline…, candidate, residual]` whose candidate column is ignored.
pub fn fit_baseline(blocks: &[Block]) -> Option<DVector<f64>> {
    let m = blocks.first()?.0.nrows();
    let mut all = DMatrix::zeros(m, m);
    for b in blocks {
        all += &b.0;
    }
    let baseline: Vec<usize> = (0..m - 2).collect();
    let beta = coefficients(&all, &baseline)?;
    Some(beta.rows(1, m - 3).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blocks(groups: &[Vec<Vec<f64>>]) -> Vec<Block> {
        groups
            .iter()
            .map(|columns| {
                let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
                Block::of(&refs).centred()
            })
            .collect()
    }

    /// Twenty activations whose residual is 2 × a baseline column + 0.5 × an independent shape +
    /// a little noise: the baseline explains its part, the independent candidate gains its own
    /// share beyond it, and a candidate that is the baseline column again gains nothing.
    #[test]
    fn a_candidate_gains_what_the_baseline_leaves_and_nothing_it_explains() {
        let folds: Vec<usize> = (0..20).map(|i| i % 5).collect();
        let make = |candidate_is_baseline: bool| -> Vec<Vec<Vec<f64>>> {
            (0..20)
                .map(|a| {
                    let t: Vec<f64> = (0..100).map(|i| f64::from(i) / 100.0).collect();
                    let base: Vec<f64> =
                        t.iter().map(|t| (t * (3.0 + f64::from(a))).sin()).collect();
                    let other: Vec<f64> =
                        t.iter().map(|t| t * t * (1.0 + f64::from(a % 3))).collect();
                    let noise: Vec<f64> = t
                        .iter()
                        .map(|t| 0.01 * (t * 977.0 + f64::from(a)).sin())
                        .collect();
                    let y: Vec<f64> = (0..100)
                        .map(|i| 2.0 * base[i] + 0.5 * other[i] + noise[i])
                        .collect();
                    let candidate = if candidate_is_baseline {
                        base.clone()
                    } else {
                        other
                    };
                    vec![base, candidate, y]
                })
                .collect()
        };
        let cv = cross_validate(&blocks(&make(false)), &folds, 5, None);
        assert!(cv.stable);
        let (b, g) = (cv.baseline_share(), cv.gain());
        assert!(
            b > 0.5 && g > 0.05 && b + g > 0.99,
            "baseline {b}, gain {g}"
        );
        let same = cross_validate(&blocks(&make(true)), &folds, 5, None);
        assert!(same.gain() < 1e-6, "{}", same.gain());
    }

    /// Without baseline columns the gain is the plain cross-validated share, and the blocks of an
    /// activation as one point (its means) score offsets between activations.
    #[test]
    fn without_a_baseline_the_gain_is_the_explained_share() {
        let groups: Vec<Vec<Vec<f64>>> = (0..10)
            .map(|g| {
                let x: Vec<f64> = (0..20).map(|k| f64::from(g * 20 + k)).collect();
                let y: Vec<f64> = x.iter().map(|x| 2.0 * x + 1.0).collect();
                vec![x, y]
            })
            .collect();
        let folds: Vec<usize> = (0..10).map(|g| g % 5).collect();
        let means: Vec<Block> = groups
            .iter()
            .map(|c| Block::of(&[&c[0], &c[1]]).means())
            .collect();
        let cv = cross_validate(&means, &folds, 5, None);
        assert!((cv.gain() - 1.0).abs() < 1e-9, "{}", cv.gain());
        assert_eq!(cv.baseline_share(), 0.0);
        // Non-finite rows are left out of a block.
        let block = Block::of(&[&[1.0, f64::NAN, 3.0], &[2.0, 5.0, 6.0]]);
        assert_eq!(block.rows(), 2.0);
        assert_eq!(block.0[(1, 2)], 1.0 * 2.0 + 3.0 * 6.0);
    }
}
