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

/// [`centred_moving_average`] of `K` channels at once, evaluated only at the indices asked for.
///
/// One pass keeps a running sum per channel (`K` independent additions per sample, which the CPU
/// overlaps, instead of one dependent chain per channel); [`Self::at`] then costs one subtraction
/// and one division. Each channel is summed in the same order and averaged with the same formula
/// as [`centred_moving_average`], so the values are the same bits.
#[derive(Debug, Clone)]
pub struct CentredAverages<const K: usize> {
    prefix: Vec<[f64; K]>,
    half_before: usize,
    half_after: usize,
}

impl<const K: usize> CentredAverages<K> {
    /// Running sums of `samples`, each holding one value per channel.
    pub fn new(samples: impl ExactSizeIterator<Item = [f64; K]>, window: usize) -> Self {
        let half_before = window / 2;
        let half_after = window.saturating_sub(1) - half_before.min(window.saturating_sub(1));
        let mut prefix = Vec::with_capacity(samples.len() + 1);
        let mut sum = [0.0_f64; K];
        prefix.push(sum);
        prefix.extend(samples.map(|x| {
            for (s, x) in sum.iter_mut().zip(x) {
                *s += x;
            }
            sum
        }));
        Self {
            prefix,
            half_before,
            half_after,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.prefix.len() - 1
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The centred average of channel `k` around sample `i` (`i < len`, `k < K`).
    #[inline]
    pub fn at(&self, i: usize, k: usize) -> f64 {
        let lo = i.saturating_sub(self.half_before);
        let hi = (i + self.half_after + 1).min(self.len());
        (self.prefix[hi][k] - self.prefix[lo][k]) / (hi - lo) as f64
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

    #[test]
    fn several_channels_at_chosen_indices_are_the_same_bits() {
        let a: Vec<f32> = (0..5000)
            .map(|i| ((i * 37 % 101) as f32 - 50.0) * 0.013)
            .collect();
        let b: Vec<i16> = (0..5000).map(|i| (6000 + i / 7) as i16).collect();
        for window in [1, 2, 999, 1000, 7000] {
            let samples = a
                .iter()
                .zip(&b)
                .map(|(&x, &y)| [f64::from(x), f64::from(y)]);
            let both = CentredAverages::new(samples, window);
            let (wa, wb) = (
                centred_moving_average(&a, window),
                centred_moving_average(&b, window),
            );
            for i in 0..a.len() {
                assert_eq!(both.at(i, 0).to_bits(), wa[i].to_bits());
                assert_eq!(both.at(i, 1).to_bits(), wb[i].to_bits());
            }
        }
    }
}
