//! The low-pass evaluated only where the analysis uses it: the windows of
//! [`centred_moving_average`](crate::lowpass::centred_moving_average) around every `step`-th
//! sample, from running sums recorded only where a window starts or ends.
//!
//! A full-length running sum of six channels (48 bytes a sample, written and read back) cost more
//! than the additions themselves, for averages kept every 10th sample. Instead the caller adds the
//! samples in one pass and records its running sums at [`Windows::records`]; [`Windows::averages`]
//! then takes each window's difference of two records and divides, contiguously (vectorised) for
//! all windows that are not cut by an end. Each channel is summed in the same order and averaged
//! with the same formula as `centred_moving_average`, so the values are the same bits.

use std::ops::Range;

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Where the windows of `window` samples around the samples `(0..end).step_by(step)` start and end.
///
/// Away from the ends, windows start at `i − window/2` for `i` a multiple of `step` and end a
/// window's length later, so every boundary lies on one lattice of spacing gcd(`step`, `window`):
/// 10 samples for the defaults, one record per grid point instead of one per sample. Windows that
/// reach past an end are cut there: they start at sample 0 or end at the last window's end, which
/// are recorded too.
#[derive(Debug, Clone, Copy)]
pub struct Windows {
    n: usize,
    half_before: usize,
    half_after: usize,
    step: usize,
    queries: usize,
    spacing: usize,
    offset: usize,
    /// The last window's end: where the pass stops.
    last: usize,
    /// Lattice points up to `last`.
    lattice_points: usize,
    /// Lattice points from one window's start to the next one's, and to its end.
    per_query: usize,
    cells: usize,
    /// Lattice point of the (uncut) start of window 0, negated.
    first: usize,
}

impl Windows {
    /// The windows of `window` samples (the low-pass's) around `(0..end).step_by(step)` among `n`
    /// samples (`end` is capped at `n`).
    pub fn new(n: usize, window: usize, (end, step): (usize, usize)) -> Self {
        let half_before = window / 2;
        let half_after = window.saturating_sub(1) - half_before.min(window.saturating_sub(1));
        let width = half_before + half_after + 1;
        let step = step.max(1);
        let queries = end.min(n).div_ceil(step);
        let spacing = gcd(step, width);
        let offset = (spacing - half_before % spacing) % spacing;
        let last = match queries {
            0 => 0,
            q => ((q - 1) * step + half_after + 1).min(n),
        };
        let lattice_points = if queries == 0 || offset > last {
            0
        } else {
            (last - offset) / spacing + 1
        };
        Self {
            n,
            half_before,
            half_after,
            step,
            queries,
            spacing,
            offset,
            last,
            lattice_points,
            per_query: step / spacing,
            cells: width / spacing,
            first: (half_before + offset) / spacing,
        }
    }

    /// Where the running sums are to be recorded, ascending (none without windows): record `r` is
    /// the sum of the samples before the `r`-th position. Sample 0 first, the lattice points, then
    /// the last window's end, which is where the pass may stop.
    pub fn records(&self) -> impl Iterator<Item = usize> {
        let (offset, spacing) = (self.offset, self.spacing);
        let lattice = (0..self.lattice_points).map(move |j| offset + j * spacing);
        let ends = usize::from(self.queries > 0);
        std::iter::repeat_n(0, ends)
            .chain(lattice)
            .chain(std::iter::repeat_n(self.last, ends))
    }

    /// [`Self::records`] as a lattice: `(first, spacing, points, last)` — sample 0, then `points`
    /// lattice points `first + j·spacing`, then `last` (none of it without windows).
    pub fn lattice(&self) -> (usize, usize, usize, usize) {
        (self.offset, self.spacing, self.lattice_points, self.last)
    }

    /// Number of records ([`Self::records`]).
    pub fn record_count(&self) -> usize {
        match self.queries {
            0 => 0,
            _ => self.lattice_points + 2,
        }
    }

    /// Window `q`: the records at its start and at its end, and its number of samples.
    fn window(&self, q: usize) -> (usize, usize, usize) {
        let i = q * self.step;
        let start = i.saturating_sub(self.half_before);
        let end = (i + self.half_after + 1).min(self.n);
        // An uncut start `q·step − half_before` is lattice point `(start − offset) / spacing`
        // (record + 1), and its end `cells` lattice points later: no division per window.
        let record = (1 + q * self.per_query).wrapping_sub(self.first);
        let from = if start == 0 { 0 } else { record };
        let to = if end == self.last {
            self.lattice_points + 1
        } else {
            record.wrapping_add(self.cells)
        };
        (from, to, end - start)
    }

    /// The windows cut by neither end: those start after sample 0 and end before the last
    /// window's end.
    fn uncut(&self) -> Range<usize> {
        let from = (self.half_before / self.step + 1).min(self.queries);
        // Uncut ends `q·step + half_after + 1` below `last`.
        let to = (self.last.saturating_sub(self.half_after + 1))
            .div_ceil(self.step)
            .min(self.queries);
        from..to.max(from)
    }

    /// Every window's average of one channel, from the channel's running sums recorded at
    /// [`Self::records`], each passed through `finish`, in order.
    ///
    /// The uncut windows read the records at a fixed stride (contiguously for the defaults) and all
    /// have the same length, so their subtractions, divisions and `finish` vectorise.
    pub fn averages<T>(&self, records: &[f64], finish: impl Fn(f64) -> T) -> Vec<T> {
        let average = |q: usize| {
            let (from, to, samples) = self.window(q);
            finish((records[to] - records[from]) / samples as f64)
        };
        let uncut = self.uncut();
        let mut out = Vec::with_capacity(self.queries);
        out.extend((0..uncut.start).map(average));
        if self.per_query == 1 && !uncut.is_empty() {
            let samples = (self.cells * self.spacing) as f64;
            let starts = self.window(uncut.start).0..self.window(uncut.end - 1).0 + 1;
            let ends = starts.start + self.cells..starts.end + self.cells;
            out.extend(
                (records[starts].iter().zip(&records[ends]))
                    .map(|(&start, &end)| finish((end - start) / samples)),
            );
        } else {
            out.extend(uncut.clone().map(average));
        }
        out.extend((uncut.end..self.queries).map(average));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lowpass::centred_moving_average;

    /// Two channels of `n` samples, one f32-like and one integer-like.
    fn channels(n: usize) -> (Vec<f32>, Vec<i16>) {
        let a = (0..n)
            .map(|i| ((i * 37 % 101) as f32 - 50.0) * 0.013)
            .collect();
        let b = (0..n).map(|i| (6000 + i / 7) as i16).collect();
        (a, b)
    }

    /// Averages of both channels at `(0..end).step_by(step)`, the way the analysis computes them.
    fn sparse(a: &[f32], b: &[i16], window: usize, end: usize, step: usize) -> [Vec<f64>; 2] {
        let windows = Windows::new(a.len(), window, (end, step));
        let mut records: [Vec<f64>; 2] = Default::default();
        let (mut sums, mut added) = ([0.0_f64; 2], 0);
        let positions: Vec<usize> = windows.records().collect();
        assert_eq!(positions.len(), windows.record_count());
        assert!(positions.windows(2).all(|w| w[0] <= w[1]));
        for position in positions {
            for (x, y) in a[added..position].iter().zip(&b[added..position]) {
                sums[0] += f64::from(*x);
                sums[1] += f64::from(*y);
            }
            added = position;
            records[0].push(sums[0]);
            records[1].push(sums[1]);
        }
        records.map(|r| windows.averages(&r, |average| average))
    }

    #[test]
    fn several_channels_at_chosen_indices_are_the_same_bits() {
        let (a, b) = channels(5000);
        for window in [1, 2, 999, 1000, 7000] {
            let (wa, wb) = (
                centred_moving_average(&a, window),
                centred_moving_average(&b, window),
            );
            for (end, step) in [
                (5000, 1),
                (5000, 10),
                (5000, 997),
                (4000, 1),
                (1, 3),
                (0, 1),
            ] {
                let [ga, gb] = sparse(&a, &b, window, end, step);
                let at: Vec<usize> = (0..end).step_by(step).collect();
                assert_eq!((ga.len(), gb.len()), (at.len(), at.len()));
                for (k, &i) in at.iter().enumerate() {
                    assert_eq!(ga[k].to_bits(), wa[i].to_bits());
                    assert_eq!(gb[k].to_bits(), wb[i].to_bits());
                }
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn any_window_step_and_end_give_the_full_average_s_bits(
            n in 1_usize..3000,
            window in 1_usize..4000,
            step in 1_usize..50,
            end in 0_usize..3500,
        ) {
            let (a, b) = channels(n);
            let at: Vec<usize> = (0..end.min(n)).step_by(step).collect();
            let (wa, wb) = (centred_moving_average(&a, window), centred_moving_average(&b, window));
            let [ga, gb] = sparse(&a, &b, window, end, step);
            proptest::prop_assert_eq!((ga.len(), gb.len()), (at.len(), at.len()));
            for (k, &i) in at.iter().enumerate() {
                proptest::prop_assert_eq!(ga[k].to_bits(), wa[i].to_bits());
                proptest::prop_assert_eq!(gb[k].to_bits(), wb[i].to_bits());
            }
        }
    }
}
