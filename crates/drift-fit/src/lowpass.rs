//! The paper's low-pass: a centred sliding-window average.

/// Centred moving average of `window` samples (shrinking at both ends, so the output has the input's
/// length and no lag). O(n) with a running sum in f64.
pub fn centred_moving_average<T: Copy + Into<f64>>(input: &[T], window: usize) -> Vec<f64> {
    let n = input.len();
    let half_before = window / 2;
    let half_after = window.saturating_sub(1) - half_before.min(window.saturating_sub(1));
    let mut prefix = Vec::with_capacity(n + 1);
    let mut sum = 0.0_f64;
    prefix.push(0.0);
    for &x in input {
        sum += x.into();
        prefix.push(sum);
    }
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(half_before);
            let hi = (i + half_after + 1).min(n);
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Where [`centred_moving_average`]'s windows around the samples `(0..end).step_by(step)` start
/// and end, so that a pass over the samples can record its running sums only there (see
/// [`for_each_window`]).
///
/// Away from the ends, windows start at `i − window/2` for `i` a multiple of `step` and end a
/// window's length later, so every boundary lies on one lattice, of spacing gcd(`step`, `window`)
/// (10 samples for the defaults: one record per grid point instead of one per sample). Windows
/// that reach past an end are cut there: they start at sample 0 or end at the last window's end,
/// which are recorded too.
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
    /// Records of lattice points up to `last`.
    lattice_points: usize,
    /// Lattice points from one window's start to the next one's, and to its end.
    per_query: usize,
    cells: usize,
    /// Lattice point of the (unclamped) start of window 0, negated.
    first: usize,
}

impl Windows {
    /// The windows of `window` samples (the low-pass's) around `(0..end).step_by(step)` among `n`
    /// samples (`end` is capped at `n`).
    pub fn new(n: usize, window: usize, (end, step): (usize, usize)) -> Self {
        let half_before = window / 2;
        let half_after = window.saturating_sub(1) - half_before.min(window.saturating_sub(1));
        let step = step.max(1);
        let queries = end.min(n).div_ceil(step);
        let spacing = gcd(step, half_before + half_after + 1);
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
            cells: (half_before + half_after + 1) / spacing,
            first: (half_before + offset) / spacing,
        }
    }

    /// Number of windows.
    pub fn len(&self) -> usize {
        self.queries
    }

    /// Whether there are no windows.
    pub fn is_empty(&self) -> bool {
        self.queries == 0
    }

    /// Where the running sums are recorded, ascending: record `r` is the sum of the samples before
    /// the `r`-th position. Sample 0 first, the lattice points, then the last window's end.
    pub fn records(&self) -> impl Iterator<Item = usize> {
        let (offset, spacing) = (self.offset, self.spacing);
        let lattice = (0..self.lattice_points).map(move |j| offset + j * spacing);
        std::iter::once(0)
            .chain(lattice)
            .chain(std::iter::once(self.last))
    }

    /// Window `q`: the records at its start and at its end, and its number of samples (as f64,
    /// the divisor of the average).
    #[inline]
    pub fn window(&self, q: usize) -> (usize, usize, f64) {
        let i = q * self.step;
        let start = i.saturating_sub(self.half_before);
        let end = (i + self.half_after + 1).min(self.n);
        // An unclamped start `q·step − half_before` is lattice point `(start − offset) / spacing`
        // (record + 1), and its end `cells` lattice points later: computed without a division.
        let record = (1 + q * self.per_query).wrapping_sub(self.first);
        let from = if start == 0 { 0 } else { record };
        let to = if end == self.last {
            self.lattice_points + 1
        } else {
            record.wrapping_add(self.cells)
        };
        (from, to, (end - start) as f64)
    }
}

/// One pass of [`centred_moving_average`] over `K` channels, for the windows of `windows` only:
/// `add(range, sums)` adds samples `range` to the `K` running sums in order, and
/// `window(q, sums, samples)` receives each window's sums as soon as its last sample is added, in
/// order. `sums[k] / samples` is then channel `k`'s average, the same bits as
/// [`centred_moving_average`]'s (each channel is summed in the same order, and a window's sum is
/// the same difference of running sums).
///
/// The running sums are recorded only at window boundaries, never per sample: a full-length running
/// sum of six channels (48 bytes a sample, written and read back) cost more than the additions. A
/// window is finished (its sums and the caller's division) right after its last cell is added,
/// where the divisions overlap the next cell's additions instead of needing a pass of their own.
/// Inlined, so that `add` and `window` are too and the sums stay in registers.
#[inline(always)]
pub fn for_each_window<const K: usize>(
    windows: &Windows,
    mut add: impl FnMut(std::ops::Range<usize>, &mut [f64; K]),
    mut window: impl FnMut(usize, [f64; K], f64),
) {
    if windows.is_empty() {
        return;
    }
    let mut records: Vec<[f64; K]> = Vec::with_capacity(windows.lattice_points + 2);
    let mut running = [0.0_f64; K];
    let (mut added, mut next) = (0, 0);
    for (record, position) in windows.records().enumerate() {
        add(added..position, &mut running);
        added = position;
        records.push(running);
        while next < windows.queries {
            let (from, to, samples) = windows.window(next);
            if to != record {
                break;
            }
            let mut sums = running;
            for (sum, start) in sums.iter_mut().zip(records[from]) {
                *sum -= start;
            }
            window(next, sums, samples);
            next += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn averages_a_centred_window_and_shrinks_at_the_ends() {
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let y = centred_moving_average(&x, 4);
        // Window of 4 around i covers i−2 ..= i+1.
        assert_eq!(y[5], (3.0 + 4.0 + 5.0 + 6.0) / 4.0);
        assert_eq!(y[0], (0.0 + 1.0) / 2.0);
        assert_eq!(y[9], (7.0 + 8.0 + 9.0) / 3.0);
        // A linear ramp is preserved in the interior by an odd window.
        let y = centred_moving_average(&x, 3);
        assert!((y[4] - 4.0).abs() < 1e-12);
        assert_eq!(centred_moving_average::<f64>(&[], 5), Vec::<f64>::new());
        assert_eq!(centred_moving_average(&[2.0_f32], 1000), vec![2.0]);
    }

    /// Two channels of `n` samples, one f32-like and one integer-like.
    fn channels(n: usize) -> (Vec<f32>, Vec<i16>) {
        let a = (0..n)
            .map(|i| ((i * 37 % 101) as f32 - 50.0) * 0.013)
            .collect();
        let b = (0..n).map(|i| (6000 + i / 7) as i16).collect();
        (a, b)
    }

    /// Averages of both channels at `(0..end).step_by(step)`.
    fn sparse(a: &[f32], b: &[i16], window: usize, end: usize, step: usize) -> Vec<[f64; 2]> {
        let windows = Windows::new(a.len(), window, (end, step));
        let (mut added, mut out) = (0, Vec::new());
        for_each_window(
            &windows,
            |range, sum: &mut [f64; 2]| {
                assert_eq!(range.start, added, "samples are added in order, each once");
                added = range.end;
                for (x, y) in a[range.clone()].iter().zip(&b[range]) {
                    sum[0] += f64::from(*x);
                    sum[1] += f64::from(*y);
                }
            },
            |q, sums, samples| {
                assert_eq!(q, out.len(), "windows come in order");
                out.push(sums.map(|sum| sum / samples));
            },
        );
        assert_eq!(out.len(), windows.len());
        out
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
                let both = sparse(&a, &b, window, end, step);
                let at: Vec<usize> = (0..end).step_by(step).collect();
                assert_eq!(both.len(), at.len());
                for (&i, got) in at.iter().zip(&both) {
                    assert_eq!(got[0].to_bits(), wa[i].to_bits());
                    assert_eq!(got[1].to_bits(), wb[i].to_bits());
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
            let both = sparse(&a, &b, window, end, step);
            proptest::prop_assert_eq!(both.len(), at.len());
            for (&i, got) in at.iter().zip(&both) {
                proptest::prop_assert_eq!(got[0].to_bits(), wa[i].to_bits());
                proptest::prop_assert_eq!(got[1].to_bits(), wb[i].to_bits());
            }
        }
    }
}
