//! The closed loop's significance tests: whether a mean gain is above zero, and whether a model
//! choice paired by activation is taken.

fn standard_normal_tail(z: f64) -> f64 {
    // Upper tail of N(0,1) via the complementary error function (Abramowitz–Stegun 7.1.26).
    let t = 1.0 / (1.0 + 0.3275911 * z.abs() / std::f64::consts::SQRT_2);
    let poly = t
        * (0.254829592
            + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    let erfc = poly * (-(z * z) / 2.0).exp();
    if z >= 0.0 {
        0.5 * erfc
    } else {
        1.0 - 0.5 * erfc
    }
}

/// The mean of `gains` and the one-sided p-value of "the mean is above zero" (normal approximation
/// of the t statistic; the gains are per activation, so there are dozens).
pub fn one_sided_mean_test(gains: &[f64]) -> (f64, f64) {
    let n = gains.len() as f64;
    let mean = gains.iter().sum::<f64>() / n.max(1.0);
    let sd = (gains.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    let z = if sd > 0.0 {
        mean / (sd / n.sqrt())
    } else {
        0.0
    };
    (mean, standard_normal_tail(z))
}

/// Significance level of the loop's model choices (stage 3's lookup, the initial bias): the
/// guard's.
const CHOOSE_ALPHA: f64 = 0.05;

/// A model choice on one axis, paired by activation.
pub struct PairedChoice {
    /// Mean of the current model's per-activation error (NaN without activations).
    pub current: f64,
    /// Mean of the alternative's.
    pub alternative: f64,
    /// One-sided p-value of "the alternative leaves less error".
    pub p_value: f64,
    /// Whether the alternative is taken: a smaller mean error, significant at 5 %. Fewer than two
    /// activations choose nothing.
    pub chosen: bool,
}

/// The choice on `axis` from per-activation errors `(current, alternative)` per axis.
pub fn paired_choice(errors: &[([f64; 3], [f64; 3])], axis: usize) -> PairedChoice {
    let n = errors.len();
    let mean = |alternative: bool| {
        if n == 0 {
            f64::NAN
        } else {
            let sum: f64 = errors
                .iter()
                .map(|(c, a)| if alternative { a[axis] } else { c[axis] })
                .sum();
            sum / n as f64
        }
    };
    let (current, alternative) = (mean(false), mean(true));
    let gains: Vec<f64> = errors.iter().map(|(c, a)| c[axis] - a[axis]).collect();
    let (p_value, chosen) = if n < 2 {
        (1.0, false)
    } else {
        let (gain, p_value) = one_sided_mean_test(&gains);
        (p_value, gain > 0.0 && p_value < CHOOSE_ALPHA)
    };
    PairedChoice {
        current,
        alternative,
        p_value,
        chosen,
    }
}
