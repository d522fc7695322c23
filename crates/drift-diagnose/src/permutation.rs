//! How large an explained share chance alone reaches on one axis, measured on the data diagnosed.
//!
//! Every candidate is scored again with the activations' candidates shuffled among activations of
//! the same unit and set point: each activation's residual is paired with another activation's
//! candidate values, which keeps everything about both (their shapes, their spread, the heating
//! they share) except a relation between this residual and that candidate. The largest share any
//! candidate reaches in one shuffle is a draw from the null distribution of the ranking's winner
//! (the Westfall–Young max statistic), so comparing a candidate's share with those maxima corrects
//! for the number of candidates, their correlation and the autocorrelation inside activations,
//! without a formula that assumes any of them away. The same maxima say how large an effect must
//! be for these activations to show it.
//!
//! The statistic is the out-of-sample explained share, cross-validated with the diagnosis's folds
//! (whole series held out together), at whichever level is larger — within activations (shapes)
//! or between them (offsets) — and counted only when every fold's coefficient has the same sign.

use std::collections::BTreeMap;

use rand::rngs::ChaCha8Rng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;

/// Shuffles per axis: the smallest p-value they can give is 1 / (SHUFFLES + 1) = 0.01.
pub const SHUFFLES: usize = 99;

/// Sums of one activation's (candidate, residual) pairs: count, Σx, Σy, Σx², Σxy, Σy².
#[derive(Debug, Clone, Copy, Default)]
struct Sums {
    n: f64,
    x: f64,
    y: f64,
    xx: f64,
    xy: f64,
    yy: f64,
}

impl Sums {
    fn of(residual: &[f64], candidate: &[f64]) -> Self {
        let mut s = Self::default();
        for (&y, &x) in residual.iter().zip(candidate) {
            if x.is_finite() && y.is_finite() {
                s.n += 1.0;
                s.x += x;
                s.y += y;
                s.xx += x * x;
                s.xy += x * y;
                s.yy += y * y;
            }
        }
        s
    }

    fn add(&mut self, other: &Self) {
        self.n += other.n;
        self.x += other.x;
        self.y += other.y;
        self.xx += other.xx;
        self.xy += other.xy;
        self.yy += other.yy;
    }

    /// The same points less their own means: what a shape is scored on.
    fn centred(self) -> Self {
        if self.n <= 0.0 {
            return Self::default();
        }
        Self {
            n: self.n,
            x: 0.0,
            y: 0.0,
            xx: self.xx - self.x * self.x / self.n,
            xy: self.xy - self.x * self.y / self.n,
            yy: self.yy - self.y * self.y / self.n,
        }
    }

    /// The single point (mean candidate, mean residual): what an offset is scored on.
    fn means(self) -> Self {
        if self.n <= 0.0 {
            return Self::default();
        }
        let (x, y) = (self.x / self.n, self.y / self.n);
        Self {
            n: 1.0,
            x,
            y,
            xx: x * x,
            xy: x * y,
            yy: y * y,
        }
    }

    /// Squared error of `y ≈ intercept + slope · x` over these points.
    fn squared_error(&self, slope: f64, intercept: f64) -> f64 {
        let (a, b) = (intercept, slope);
        (self.yy - 2.0 * a * self.y - 2.0 * b * self.xy
            + a * a * self.n
            + 2.0 * a * b * self.x
            + b * b * self.xx)
            .max(0.0)
    }
}

/// Cross-validated explained share of one level's groups, or 0 when the folds' coefficients
/// disagree in sign (or nothing is left to explain).
fn explained(groups: &[Sums], fold_of: &[usize], folds: usize) -> f64 {
    let mut all = Sums::default();
    for g in groups {
        all.add(g);
    }
    if all.n < 2.0 {
        return 0.0;
    }
    let total = all.yy - all.y * all.y / all.n;
    if total <= 0.0 {
        return 0.0;
    }
    let (mut sse, mut positive, mut negative) = (0.0, false, false);
    for fold in 0..folds {
        let mut train = Sums::default();
        for (g, _) in groups.iter().zip(fold_of).filter(|(_, &f)| f != fold) {
            train.add(g);
        }
        if train.n < 2.0 {
            continue;
        }
        let sxx = train.xx - train.x * train.x / train.n;
        let sxy = train.xy - train.x * train.y / train.n;
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        let intercept = (train.y - slope * train.x) / train.n;
        positive |= slope > 0.0;
        negative |= slope < 0.0;
        sse += groups
            .iter()
            .zip(fold_of)
            .filter(|(_, &f)| f == fold)
            .map(|(g, _)| g.squared_error(slope, intercept))
            .sum::<f64>();
    }
    if positive && negative {
        return 0.0;
    }
    (1.0 - sse / total).max(0.0)
}

/// What is scored on one axis: per activation, its residual, its candidates by name, and the
/// stratum it may be shuffled within; and the cross-validation folds.
#[derive(Debug, Clone, Copy)]
pub struct Scored<'a> {
    /// Each activation's residual.
    pub residuals: &'a [&'a [f64]],
    /// Each activation's candidates (what the tables leave of them), by name.
    pub candidates: &'a [&'a BTreeMap<String, Vec<f64>>],
    /// Each activation's stratum: candidates are shuffled among activations of one stratum.
    pub strata: &'a [usize],
    /// The fold each activation is held out in.
    pub fold_of: &'a [usize],
    /// How many folds.
    pub folds: usize,
}

/// Where a statistic comes from: offsets between activations or shapes within them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Shapes within activations (each activation less its means).
    Within,
    /// Offsets between activations (one point per activation: its means).
    Between,
}

impl Scored<'_> {
    /// The statistic of one candidate with activation `i`'s residual paired with activation
    /// `pairing[i]`'s candidate values, and the level it comes from.
    fn statistic(&self, name: &str, pairing: &[usize]) -> (f64, Level) {
        let sums: Vec<Sums> = self
            .residuals
            .iter()
            .zip(pairing)
            .map(|(residual, &j)| {
                self.candidates
                    .get(j)
                    .and_then(|c| c.get(name))
                    .map_or_else(Sums::default, |c| Sums::of(residual, c))
            })
            .collect();
        let within: Vec<Sums> = sums.iter().map(|s| s.centred()).collect();
        let between: Vec<Sums> = sums.iter().map(|s| s.means()).collect();
        let within = explained(&within, self.fold_of, self.folds);
        let between = explained(&between, self.fold_of, self.folds);
        if within >= between {
            (within, Level::Within)
        } else {
            (between, Level::Between)
        }
    }
}

/// The null distribution of the largest explained share among `names` on one axis, and each
/// candidate's share on the data as recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct Null {
    /// Each candidate's statistic on the data as recorded, and the level it comes from.
    pub observed: BTreeMap<String, (f64, Level)>,
    /// The largest statistic of any candidate in each shuffle, ascending.
    pub maxima: Vec<f64>,
}

impl Null {
    /// Scores `names` as recorded and under [`SHUFFLES`] shuffles of the candidates within each
    /// stratum. Deterministic: the shuffles are seeded by `seed` and their number.
    pub fn measure(scored: &Scored, names: &[String], seed: u64) -> Self {
        let identity: Vec<usize> = (0..scored.residuals.len()).collect();
        let observed = names
            .par_iter()
            .map(|n| (n.clone(), scored.statistic(n, &identity)))
            .collect();
        let mut strata: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (i, &s) in scored.strata.iter().enumerate().take(identity.len()) {
            strata.entry(s).or_default().push(i);
        }
        let mut maxima: Vec<f64> = (0..SHUFFLES)
            .into_par_iter()
            .map(|k| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1 << 20) ^ k as u64);
                let mut pairing = identity.clone();
                for members in strata.values() {
                    let mut shuffled = members.clone();
                    shuffled.shuffle(&mut rng);
                    for (&i, &j) in members.iter().zip(&shuffled) {
                        pairing[i] = j;
                    }
                }
                names
                    .iter()
                    .map(|n| scored.statistic(n, &pairing).0)
                    .fold(0.0, f64::max)
            })
            .collect();
        maxima.sort_by(f64::total_cmp);
        Self { observed, maxima }
    }

    /// Share of shuffles whose best candidate reached `share` (with the data as recorded counted
    /// as one of them): the family-wise p-value of a candidate with that share.
    pub fn p_value(&self, share: f64) -> f64 {
        let reached = self.maxima.iter().filter(|&&m| m >= share).count();
        (1 + reached) as f64 / (1 + self.maxima.len()) as f64
    }

    /// The share a candidate must exceed to be significant at `alpha`: the smallest effect these
    /// activations can show, as a share of the residual's variance.
    pub fn detectable(&self, alpha: f64) -> f64 {
        let n = self.maxima.len();
        if n == 0 {
            return 1.0;
        }
        // p ≤ alpha needs at most ⌊alpha·(n + 1)⌋ − 1 maxima at or above the share.
        let allowed = ((alpha * (n + 1) as f64).floor() as usize).saturating_sub(1);
        self.maxima
            .get(n - 1 - allowed.min(n - 1))
            .copied()
            .unwrap_or(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cross_validated_share_of_a_line_and_of_noise() {
        // Ten groups on y = 2x: explained fully, same sign in every fold.
        let line: Vec<Sums> = (0..10)
            .map(|g| {
                let x: Vec<f64> = (0..20).map(|k| (g * 20 + k) as f64).collect();
                let y: Vec<f64> = x.iter().map(|x| 2.0 * x).collect();
                Sums::of(&y, &x)
            })
            .collect();
        let folds: Vec<usize> = (0..10).map(|g| g % 5).collect();
        assert!((explained(&line, &folds, 5) - 1.0).abs() < 1e-9);
        // Groups whose relation flips sign between folds count nothing: fold 0's groups run
        // steeply the other way, so every fold trained with them has a negative slope and the one
        // trained without them a positive one.
        let flipping: Vec<Sums> = (0..10)
            .map(|g| {
                let x: Vec<f64> = (0..20).map(f64::from).collect();
                let sign = if g % 5 == 0 { -100.0 } else { 1.0 };
                let y: Vec<f64> = x.iter().map(|x| sign * x * (1.0 + g as f64)).collect();
                Sums::of(&y, &x).centred()
            })
            .collect();
        assert_eq!(explained(&flipping, &folds, 5), 0.0);
    }

    #[test]
    fn p_value_and_detectable_share_read_the_maxima() {
        let null = Null {
            observed: BTreeMap::new(),
            maxima: (1..=99).map(|k| k as f64 / 100.0).collect(),
        };
        // 0.995 beats every shuffle: p = 1/100.
        assert!((null.p_value(0.995) - 0.01).abs() < 1e-12);
        // 0.5 is reached by 50 of 99 shuffles.
        assert!((null.p_value(0.5) - 51.0 / 100.0).abs() < 1e-12);
        let detectable = null.detectable(0.05);
        assert!(null.p_value(detectable + 1e-9) <= 0.05);
        assert!(null.p_value(detectable) > 0.05 - 1e-12);
    }
}
