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
//! The statistic is a candidate's gain over the baseline: the out-of-sample share of the residual's
//! variance it explains beyond the baseline's columns ([`crate::gram`]), cross-validated with the
//! diagnosis's folds (whole series held out together), at whichever level is larger — within
//! activations (shapes) or between them (offsets) — and counted only when every fold's coefficient
//! has the same sign. Shuffles move whole series onto series: the baseline stays with the residual
//! it came with.

use std::collections::BTreeMap;

use drift_recording::{Interrupted, Progress};

use nalgebra::DMatrix;
use rand::rngs::ChaCha8Rng;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;

use crate::gram::{cross_validate, Block};

/// Shuffles per axis: the smallest p-value they can give is 1 / (SHUFFLES + 1) = 0.01.
pub const SHUFFLES: usize = 99;

/// The step [`Null::measure`] reports: shuffles done of [`SHUFFLES`].
pub const SHUFFLING: &str = "shuffling the candidates";

/// What is scored on one axis: per activation, its residual, its baseline columns (the paper
/// model's known gaps and the bench's context, [`crate::diagnose`]), its candidates by name, and
/// the stratum it may be shuffled within; and the cross-validation folds.
#[derive(Debug, Clone, Copy)]
pub struct Scored<'a> {
    /// Each activation's residual.
    pub residuals: &'a [&'a [f64]],
    /// Each activation's baseline columns, the same number for every activation.
    pub baseline: &'a [Vec<&'a [f64]>],
    /// Each activation's candidates (what the tables leave of them), by name.
    pub candidates: &'a [&'a BTreeMap<String, Vec<f64>>],
    /// Each activation's stratum: candidates are shuffled among activations of one stratum.
    pub strata: &'a [usize],
    /// The series each activation belongs to (an index, unique within its stratum): shuffles
    /// move whole series.
    pub series: &'a [usize],
    /// The fold each activation is held out in.
    pub fold_of: &'a [usize],
    /// How many folds.
    pub folds: usize,
}

/// One activation's baseline and residual, read once: the block of `[1, baseline…, residual]` and
/// the rows it counted, to which a candidate's cross products are added.
struct Own {
    block: DMatrix<f64>,
    finite: Vec<usize>,
    len: usize,
}

impl Own {
    fn of(baseline: &[&[f64]], residual: &[f64]) -> Self {
        let mut columns: Vec<&[f64]> = baseline.to_vec();
        columns.push(residual);
        let len = columns.iter().map(|c| c.len()).min().unwrap_or(0);
        let finite = (0..len)
            .filter(|&r| columns.iter().all(|c| c[r].is_finite()))
            .collect();
        Self {
            block: Block::of(&columns).0,
            finite,
            len,
        }
    }
}

/// The baseline's held-out squared error and explained share at each level.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Baselines {
    within: f64,
    between: f64,
    /// Share of the residual's variance within activations the baseline explains out of sample.
    pub within_share: f64,
    /// Share of the variance of the activations' means the baseline explains out of sample.
    pub between_share: f64,
}

impl Scored<'_> {
    fn columns<'c>(&'c self, i: usize, candidate: &'c [f64]) -> Vec<&'c [f64]> {
        let mut columns: Vec<&[f64]> = self.baseline.get(i).cloned().unwrap_or_default();
        columns.push(candidate);
        columns.push(self.residuals.get(i).copied().unwrap_or(&[]));
        columns
    }

    fn own(&self) -> Vec<Own> {
        (0..self.residuals.len())
            .map(|i| {
                Own::of(
                    self.baseline.get(i).map_or(&[][..], Vec::as_slice),
                    self.residuals[i],
                )
            })
            .collect()
    }

    /// Activation `i`'s block with `candidate` (another activation's values under a shuffle):
    /// its own part as read once, the candidate's cross products added. A shorter candidate holds
    /// its last value to the activation's end (activations of a series differ in length); one that
    /// is not finite where the rest is has the block read whole.
    fn paired(&self, i: usize, own: &Own, candidate: &[f64]) -> Block {
        let Some(&last) = candidate.last() else {
            return Block::of(&self.columns(i, candidate));
        };
        let at = |r: usize| candidate.get(r).copied().unwrap_or(last);
        if own.finite.iter().any(|&r| !at(r).is_finite()) {
            return Block::of(&self.columns(i, candidate));
        }
        let k = own.block.nrows() - 2; // baseline columns
        let m = k + 3;
        let baseline = self.baseline.get(i).map_or(&[][..], Vec::as_slice);
        let residual = self.residuals.get(i).copied().unwrap_or(&[]);
        let mut cross = vec![0.0; m];
        for &r in &own.finite {
            let x = at(r);
            cross[0] += x;
            for (c, column) in baseline.iter().enumerate() {
                cross[c + 1] += x * column[r];
            }
            cross[k + 1] += x * x;
            cross[k + 2] += x * residual[r];
        }
        let mut block = DMatrix::zeros(m, m);
        // Own indices 0..=k stay; the residual moves from k + 1 to k + 2; the candidate goes in
        // at k + 1.
        let slot = |o: usize| if o <= k { o } else { k + 2 };
        for a in 0..k + 2 {
            for b in 0..k + 2 {
                block[(slot(a), slot(b))] = own.block[(a, b)];
            }
        }
        for (j, &v) in cross.iter().enumerate() {
            block[(k + 1, j)] = v;
            block[(j, k + 1)] = v;
        }
        Block(block)
    }

    /// The statistic of one candidate with activation `i`'s residual and baseline paired with
    /// activation `pairing[i]`'s candidate values — its cross-validated gain over the baseline at
    /// the better level — and the level it comes from.
    fn statistic(
        &self,
        own: &[Own],
        baselines: &Baselines,
        name: &str,
        pairing: &[usize],
    ) -> (f64, Level) {
        let blocks: Vec<Block> = own
            .iter()
            .zip(pairing)
            .enumerate()
            .map(|(i, (own, &j))| {
                self.candidates
                    .get(j)
                    .and_then(|c| c.get(name))
                    .map_or_else(
                        || self.paired(i, own, &vec![0.0; own.len]),
                        |c| self.paired(i, own, c),
                    )
            })
            .collect();
        let within: Vec<Block> = blocks.iter().map(Block::centred).collect();
        let between: Vec<Block> = blocks.iter().map(Block::means).collect();
        let within =
            cross_validate(&within, self.fold_of, self.folds, Some(baselines.within)).gain();
        let between =
            cross_validate(&between, self.fold_of, self.folds, Some(baselines.between)).gain();
        if within >= between {
            (within, Level::Within)
        } else {
            (between, Level::Between)
        }
    }

    /// The baseline's held-out squared error at each level (no candidate changes it) and its
    /// explained shares.
    fn baselines(&self, own: &[Own]) -> Baselines {
        // A candidate column of zeros leaves the baseline's fit as it is.
        let blocks: Vec<Block> = own
            .iter()
            .enumerate()
            .map(|(i, own)| self.paired(i, own, &vec![0.0; own.len]))
            .collect();
        let within: Vec<Block> = blocks.iter().map(Block::centred).collect();
        let between: Vec<Block> = blocks.iter().map(Block::means).collect();
        let within = cross_validate(&within, self.fold_of, self.folds, None);
        let between = cross_validate(&between, self.fold_of, self.folds, None);
        Baselines {
            within: within.baseline_sse,
            between: between.baseline_sse,
            within_share: within.baseline_share(),
            between_share: between.baseline_share(),
        }
    }
}

/// Where a statistic comes from: offsets between activations or shapes within them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Shapes within activations (each activation less its means).
    Within,
    /// Offsets between activations (one point per activation: its means).
    Between,
}

/// The null distribution of the largest explained share among `names` on one axis, and each
/// candidate's share on the data as recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct Null {
    /// Each candidate's statistic on the data as recorded, and the level it comes from.
    pub observed: BTreeMap<String, (f64, Level)>,
    /// The largest statistic of any candidate in each shuffle, ascending.
    pub maxima: Vec<f64>,
    /// What the baseline explains, at each level.
    pub baselines: Baselines,
}

impl Null {
    /// Scores `names` as recorded and under [`SHUFFLES`] shuffles of the candidates within each
    /// stratum. Deterministic: the shuffles are seeded by `seed` and their number. `progress` is
    /// asked before each shuffle (`done` of [`SHUFFLES`]) whether to go on: a shuffle scores every
    /// name once, milliseconds of work.
    pub fn measure(
        scored: &Scored,
        names: &[String],
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Self, Interrupted> {
        progress.check(SHUFFLING, 0, SHUFFLES as u64)?;
        let identity: Vec<usize> = (0..scored.residuals.len()).collect();
        let own = scored.own();
        let baselines = scored.baselines(&own);
        let observed = names
            .par_iter()
            .map(|n| (n.clone(), scored.statistic(&own, &baselines, n, &identity)))
            .collect();
        // Whole series are mapped onto series of the same stratum, activation k onto activation k
        // (wrapping where the other series is shorter): a series' activations share their
        // off-times and ambient ramp, and shuffled one by one they would break that.
        let mut strata: BTreeMap<usize, BTreeMap<usize, Vec<usize>>> = BTreeMap::new();
        for (i, (&s, &series)) in scored
            .strata
            .iter()
            .zip(scored.series)
            .enumerate()
            .take(identity.len())
        {
            strata
                .entry(s)
                .or_default()
                .entry(series)
                .or_default()
                .push(i);
        }
        let mut maxima: Vec<f64> = (0..SHUFFLES)
            .into_par_iter()
            .map(|k| {
                progress.check(SHUFFLING, k as u64, SHUFFLES as u64)?;
                let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1 << 20) ^ k as u64);
                let mut pairing = identity.clone();
                for series in strata.values() {
                    // Too few series to shuffle (fewer than the folds): activation by activation,
                    // as the folds then run.
                    let single: Vec<Vec<usize>>;
                    let members: Vec<&Vec<usize>> = if series.len() < scored.folds.max(2) {
                        single = series.values().flatten().map(|&i| vec![i]).collect();
                        single.iter().collect()
                    } else {
                        series.values().collect()
                    };
                    let mut shuffled = members.clone();
                    shuffled.shuffle(&mut rng);
                    for (from, onto) in members.iter().zip(&shuffled) {
                        for (n, &i) in from.iter().enumerate() {
                            if let Some(&j) = onto.get(n % onto.len().max(1)) {
                                pairing[i] = j;
                            }
                        }
                    }
                }
                Ok(names
                    .iter()
                    .map(|n| scored.statistic(&own, &baselines, n, &pairing).0)
                    .fold(0.0, f64::max))
            })
            .collect::<Result<_, Interrupted>>()?;
        maxima.sort_by(f64::total_cmp);
        Ok(Self {
            observed,
            maxima,
            baselines,
        })
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
    use std::ops::ControlFlow;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// Groups whose relation flips sign between folds count nothing: fold 0's groups run steeply
    /// the other way, so every fold trained with them has a negative slope and the one trained
    /// without them a positive one.
    #[test]
    fn a_relation_that_flips_sign_between_folds_gains_nothing() {
        let flipping: Vec<Block> = (0..10)
            .map(|g| {
                let x: Vec<f64> = (0..20).map(f64::from).collect();
                let sign = if g % 5 == 0 { -100.0 } else { 1.0 };
                let y: Vec<f64> = x.iter().map(|x| sign * x * (1.0 + g as f64)).collect();
                Block::of(&[&x, &y]).centred()
            })
            .collect();
        let folds: Vec<usize> = (0..10).map(|g| g % 5).collect();
        assert_eq!(cross_validate(&flipping, &folds, 5, None).gain(), 0.0);
    }

    /// A candidate that carries the residual's own shape is found; a baseline column that explains
    /// the residual leaves a copy of itself nothing to gain, and the shuffles' maxima stay small.
    #[test]
    fn shuffles_of_whole_series_measure_chance_beside_the_baseline() {
        let n = 30;
        let shapes: Vec<Vec<f64>> = (0..n)
            .map(|a| {
                (0..60)
                    .map(|i| (f64::from(i) * (0.05 + 0.01 * f64::from(a % 7))).sin())
                    .collect()
            })
            .collect();
        let residuals: Vec<Vec<f64>> = shapes
            .iter()
            .enumerate()
            .map(|(a, s)| {
                s.iter()
                    .enumerate()
                    .map(|(i, v)| v + 0.05 * ((i * 31 + a * 17) as f64).sin())
                    .collect()
            })
            .collect();
        let candidates: Vec<BTreeMap<String, Vec<f64>>> = shapes
            .iter()
            .map(|s| BTreeMap::from([("shape".to_owned(), s.clone())]))
            .collect();
        let residual_refs: Vec<&[f64]> = residuals.iter().map(Vec::as_slice).collect();
        let candidate_refs: Vec<&BTreeMap<String, Vec<f64>>> = candidates.iter().collect();
        let strata = vec![0; n as usize];
        let series: Vec<usize> = (0..n as usize).map(|a| a / 3).collect();
        let fold_of: Vec<usize> = series.iter().map(|s| s % 5).collect();
        let names = ["shape".to_owned()];
        let measure = |baseline: &[Vec<&[f64]>], progress: &dyn Progress| {
            Null::measure(
                &Scored {
                    residuals: &residual_refs,
                    baseline,
                    candidates: &candidate_refs,
                    strata: &strata,
                    series: &series,
                    fold_of: &fold_of,
                    folds: 5,
                },
                &names,
                1,
                progress,
            )
        };
        let none: Vec<Vec<&[f64]>> = vec![Vec::new(); n as usize];
        let found = measure(&none, drift_recording::QUIET).expect("QUIET never stops");
        let (share, _) = found.observed["shape"];
        assert!(share > 0.9, "{share}");
        assert!(
            found.p_value(share) <= 0.02 && found.detectable(0.05) < 0.9,
            "{share} {:?}",
            found.maxima
        );
        let explained_already: Vec<Vec<&[f64]>> =
            shapes.iter().map(|s| vec![s.as_slice()]).collect();
        let known = measure(&explained_already, drift_recording::QUIET).expect("QUIET never stops");
        assert!(known.observed["shape"].0 < 1e-6, "{:?}", known.observed);
        assert!(known.baselines.within_share > 0.9);
        // Told to stop, it stops after a shuffle or so per thread, not at the end.
        let stop = StopAfter(AtomicU64::new(0), 5);
        assert_eq!(measure(&none, &stop), Err(Interrupted));
        let asked = stop.0.load(Ordering::Relaxed);
        assert!(asked < SHUFFLES as u64 / 2, "{asked}");
    }

    /// Asks to stop from its `n`-th report on, counting them.
    struct StopAfter(AtomicU64, u64);

    impl Progress for StopAfter {
        fn report(&self, _: &str, _: u64, _: u64) -> ControlFlow<()> {
            if self.0.fetch_add(1, Ordering::Relaxed) >= self.1 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    }

    #[test]
    fn p_value_and_detectable_share_read_the_maxima() {
        let null = Null {
            observed: BTreeMap::new(),
            maxima: (1..=99).map(|k| k as f64 / 100.0).collect(),
            baselines: Baselines::default(),
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
