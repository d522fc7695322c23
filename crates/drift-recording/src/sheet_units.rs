//! An activation file in another unit than the sheet's other files of its unit. One option
//! (`--rate-unit`) gives every file's unit, so a file logged in rad/s among files in °/s would be
//! read 57× too small, and would fit or judge a drift 57× too small, without a word.
//!
//! What is compared is the gyro's noise: the mean |change| of the rate from one sample to the
//! next. A unit's scale multiplies it, while the bias, the drift and the set point barely move
//! it, so activations of one sensor agree on it within a few times whatever their conditions.

use crate::segment::Segment;

/// How far (×) a file's noise may stand from the median of its siblings' before it is taken
/// for another unit: rad/s against °/s is 57×, two activations of one sensor differ by a few.
pub(crate) const OTHER_UNIT_RATIO: f64 = 15.0;

/// Siblings needed to tell which file is the odd one out (a median of at least two others).
const SIBLINGS: usize = 2;

/// Mean |rate[i+1] − rate[i]| over the axes and samples, in the segment's rate unit (°/s once
/// read); `None` when there are fewer than two samples or every step is zero (a quantised or
/// stuck output says nothing of its unit).
pub(crate) fn noise_level(segment: &Segment) -> Option<f64> {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for axis in &segment.rate_dps {
        for pair in axis.windows(2) {
            let step = f64::from(pair[1]) - f64::from(pair[0]);
            if step.is_finite() {
                sum += step.abs();
                n += 1;
            }
        }
    }
    let level = sum / n.max(1) as f64;
    (n > 0 && level > 0.0).then_some(level)
}

/// A file whose level is more than [`OTHER_UNIT_RATIO`]× away from the median of the others:
/// its index, its level divided by that median, and the median.
pub(crate) fn odd_one_out(levels: &[Option<f64>]) -> Option<(usize, f64, f64)> {
    levels.iter().enumerate().find_map(|(i, level)| {
        let level = (*level)?;
        let mut others: Vec<f64> = levels
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i)
            .filter_map(|(_, l)| *l)
            .collect();
        if others.len() < SIBLINGS {
            return None;
        }
        others.sort_by(f64::total_cmp);
        let mid = others.len() / 2;
        let median = if others.len() % 2 == 0 {
            (others[mid - 1] + others[mid]) / 2.0
        } else {
            others[mid]
        };
        let ratio = level / median;
        (!(1.0 / OTHER_UNIT_RATIO..=OTHER_UNIT_RATIO).contains(&ratio))
            .then_some((i, ratio, median))
    })
}

/// What a ratio of noise levels suggests, for the message: a file ~57× too small is in rad/s,
/// ~57× too large in °/s among rad/s.
pub(crate) fn likely_cause(ratio: f64) -> &'static str {
    let degrees_per_radian = 180.0 / std::f64::consts::PI;
    let near = |x: f64| (0.5..=2.0).contains(&x);
    if near(ratio * degrees_per_radian) {
        "it looks like rad/s among files in °/s"
    } else if near(ratio / degrees_per_radian) {
        "it looks like °/s among files in rad/s"
    } else {
        "its rate is in another unit or scale than the others'"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_57_times_quieter_is_the_odd_one_and_sensors_a_few_times_apart_are_not() {
        let levels = [Some(0.010), Some(0.012), Some(0.010 / 57.3), Some(0.008)];
        let (i, ratio, median) = odd_one_out(&levels).unwrap();
        assert_eq!(i, 2);
        assert!((median - 0.010).abs() < 1e-12 && (ratio * 57.3 - 1.0).abs() < 1e-9);
        assert_eq!(
            likely_cause(ratio),
            "it looks like rad/s among files in °/s"
        );
        assert_eq!(likely_cause(57.3), "it looks like °/s among files in rad/s");
        assert!(odd_one_out(&[Some(0.01), Some(0.03), Some(0.004), None]).is_none());
        // Two files cannot say which of them is wrong.
        assert!(odd_one_out(&[Some(0.01), Some(0.01 / 57.3)]).is_none());
    }
}
