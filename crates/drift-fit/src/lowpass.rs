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
}
