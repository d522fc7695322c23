//! Measured data the paper's method cannot be fitted on, and what can still be learnt from it.
//!
//! The paper's tables need activations that start at switch-on and warm up (a temperature rise to
//! correlate the drift with), at two or more ambients (stage 2 interpolates between them), in series
//! of power cycles with known off-times. [`obstacles`] checks a recording's activations for each and
//! names what is missing; [`NotFittable`] is the error the commands give then.
//!
//! [`characterise`] does what such data does allow, per axis:
//! - the noise floor: overlapping Allan deviation of each activation, and the spread of its 1-s
//!   means (the paper's low-frequency rate);
//! - the bias level of each activation (orientation) and its slow drift (a line against time);
//! - a 1-D bias-vs-temperature slope with its standard error, within activations (each activation's
//!   own mean removed, so orientation does not enter) and between them (activation means: confounded
//!   with orientation and day);
//! - the residual before and after a linear temperature correction whose slope is fitted without
//!   the activation it corrects (leave one activation out).
//!
//! All statistics are computed on the recording's fixed-rate grid, in f64.

use drift_recording::Segment;
use serde::Serialize;

use crate::evaluate::spread;

/// Thresholds of [`obstacles`] and the averaging window of [`characterise`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeasuredSettings {
    /// Smallest temperature rise within [`Self::warm_up_window_s`] of an activation's start that
    /// counts as a power-on warm-up, °C.
    pub min_rise_celsius: f64,
    /// Window after an activation's start in which the warm-up is looked for, s (the paper's
    /// activations last 120 s).
    pub warm_up_window_s: f64,
    /// Smallest spread of switch-on temperatures that gives two calibration ambients, °C (the
    /// paper's are 10 °C apart).
    pub min_ambient_span_celsius: f64,
    /// Averaging window of the low-frequency rate, s (the paper's 1 s).
    pub mean_window_s: f64,
}

impl Default for MeasuredSettings {
    fn default() -> Self {
        Self {
            min_rise_celsius: 1.0,
            warm_up_window_s: 120.0,
            min_ambient_span_celsius: 5.0,
            mean_window_s: 1.0,
        }
    }
}

/// Something the paper's method needs that a recording lacks.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Obstacle {
    /// No activation warms up after its start.
    NoWarmUp {
        /// The largest rise of the 1-s mean temperature over its first value within the window, °C.
        largest_rise_celsius: f64,
        /// The window, s.
        window_s: f64,
        /// The rise needed, °C.
        needed_celsius: f64,
    },
    /// The switch-on temperatures span less than two ambients.
    OneAmbient {
        /// Lowest switch-on temperature, °C.
        lowest_celsius: f64,
        /// Highest switch-on temperature, °C.
        highest_celsius: f64,
        /// The span needed, °C.
        needed_span_celsius: f64,
    },
    /// No activation belongs to a series of power cycles with a known off-time.
    NoPowerCycles {
        /// Activations looked at.
        activations: usize,
    },
}

impl std::fmt::Display for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NoWarmUp {
                largest_rise_celsius,
                window_s,
                needed_celsius,
            } => write!(
                f,
                "no power-on warm-up: the largest temperature rise in the first {window_s} s of an activation is {largest_rise_celsius:.2} °C (the tables correlate drift with a rise of at least {needed_celsius} °C)"
            ),
            Self::OneAmbient {
                lowest_celsius,
                highest_celsius,
                needed_span_celsius,
            } => write!(
                f,
                "one ambient: switch-on temperatures {lowest_celsius:.2} … {highest_celsius:.2} °C span {:.2} °C (two calibration ambients need at least {needed_span_celsius} °C between them)",
                highest_celsius - lowest_celsius
            ),
            Self::NoPowerCycles { activations } => write!(
                f,
                "no power cycles: none of the {activations} activations has a protocol off-time (series of switch-ons after known intervals)"
            ),
        }
    }
}

/// The paper's method cannot be fitted on a unit's recordings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unit {unit}: the paper's method cannot be fitted on these recordings: {}", list(.obstacles))]
pub struct NotFittable {
    /// Unit id.
    pub unit: String,
    /// Everything that is missing.
    pub obstacles: Vec<Obstacle>,
}

fn list(obstacles: &[Obstacle]) -> String {
    obstacles
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ")
}

/// Mean of `v` (NaN when empty).
fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// The mean temperature of the three axes' sensors at sample `i`, °C (NaN if none has a reading).
fn temperature(segment: &Segment, i: usize) -> f64 {
    let readings: Vec<f64> = (0..3)
        .filter_map(|a| segment.temperature_celsius(a, i))
        .filter(|c| c.is_finite())
        .collect();
    mean(&readings)
}

/// Consecutive non-overlapping means of `window` samples (a last partial window is dropped).
fn block_means(values: impl Iterator<Item = f64>, window: usize) -> Vec<f64> {
    let values: Vec<f64> = values.collect();
    values
        .chunks_exact(window.max(1))
        .map(|c| {
            let finite: Vec<f64> = c.iter().copied().filter(|v| v.is_finite()).collect();
            mean(&finite)
        })
        .collect()
}

fn window_samples(segment: &Segment, seconds: f64) -> usize {
    ((f64::from(segment.sample_rate_hz) * seconds).round() as usize).max(1)
}

/// The 1-s (settings' window) mean temperature of an activation, °C.
fn temperature_means(segment: &Segment, settings: &MeasuredSettings) -> Vec<f64> {
    block_means(
        (0..segment.len()).map(|i| temperature(segment, i)),
        window_samples(segment, settings.mean_window_s),
    )
}

/// What [`obstacles`] needs of one activation (so a long campaign can be checked file by file).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SwitchOn {
    /// The first 1-s mean temperature, °C.
    pub celsius: f64,
    /// The largest rise of the 1-s mean temperature over it within the warm-up window, °C.
    pub rise_celsius: f64,
    /// Whether the activation has a protocol off-time (belongs to a series of power cycles).
    pub has_interval: bool,
}

/// The switch-on summary of one activation (`None` if it has no temperature reading).
pub fn switch_on(segment: &Segment, settings: &MeasuredSettings) -> Option<SwitchOn> {
    let window = (settings.warm_up_window_s / settings.mean_window_s).ceil() as usize;
    let means = temperature_means(segment, settings);
    let &first = means.iter().find(|v| v.is_finite())?;
    let rise = means
        .iter()
        .take(window.max(1))
        .filter(|t| t.is_finite())
        .fold(0.0_f64, |r, t| r.max(t - first));
    Some(SwitchOn {
        celsius: first,
        rise_celsius: rise,
        has_interval: segment.labels.interval_min.is_some(),
    })
}

/// What the paper's method needs and these activations (one unit's) lack; empty if nothing.
pub fn obstacles(segments: &[Segment], settings: &MeasuredSettings) -> Vec<Obstacle> {
    let starts: Vec<SwitchOn> = segments
        .iter()
        .filter_map(|s| switch_on(s, settings))
        .collect();
    obstacles_of(&starts, segments.len(), settings)
}

/// [`obstacles`] from the activations' switch-on summaries (`activations` counts those without a
/// temperature reading too).
pub fn obstacles_of(
    starts: &[SwitchOn],
    activations: usize,
    settings: &MeasuredSettings,
) -> Vec<Obstacle> {
    let mut found = Vec::new();
    if activations == 0 {
        return found;
    }
    let largest_rise = starts.iter().map(|s| s.rise_celsius).fold(0.0, f64::max);
    if largest_rise < settings.min_rise_celsius {
        found.push(Obstacle::NoWarmUp {
            largest_rise_celsius: largest_rise,
            window_s: settings.warm_up_window_s,
            needed_celsius: settings.min_rise_celsius,
        });
    }
    let lowest = starts
        .iter()
        .map(|s| s.celsius)
        .fold(f64::INFINITY, f64::min);
    let highest = starts
        .iter()
        .map(|s| s.celsius)
        .fold(f64::NEG_INFINITY, f64::max);
    if starts.is_empty() || highest - lowest < settings.min_ambient_span_celsius {
        found.push(Obstacle::OneAmbient {
            lowest_celsius: lowest,
            highest_celsius: highest,
            needed_span_celsius: settings.min_ambient_span_celsius,
        });
    }
    if !starts.iter().any(|s| s.has_interval) {
        found.push(Obstacle::NoPowerCycles { activations });
    }
    found
}

/// A value with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard error (same unit).
    pub standard_error: f64,
}

/// Ordinary least squares of `y` on `x` (both already centred if `centred`): slope, its standard
/// error from the residuals with `dof_lost` degrees of freedom used, and the residuals.
fn slope(x: &[f64], y: &[f64], dof_lost: usize) -> Option<(Estimate, Vec<f64>)> {
    let (mx, my) = (mean(x), mean(y));
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let dof = x.len().checked_sub(dof_lost)?;
    if sxx <= 0.0 || dof == 0 {
        return None;
    }
    let b = x
        .iter()
        .zip(y)
        .map(|(a, c)| (a - mx) * (c - my))
        .sum::<f64>()
        / sxx;
    let residuals: Vec<f64> = x
        .iter()
        .zip(y)
        .map(|(a, c)| c - my - b * (a - mx))
        .collect();
    let variance = residuals.iter().map(|e| e * e).sum::<f64>() / dof as f64;
    Some((
        Estimate {
            value: b,
            standard_error: (variance / sxx).sqrt(),
        },
        residuals,
    ))
}

/// Lag-1 autocorrelation of `v` about its mean.
fn lag1(v: &[f64]) -> f64 {
    let m = mean(v);
    let denominator: f64 = v.iter().map(|x| (x - m).powi(2)).sum();
    if denominator <= 0.0 {
        return 0.0;
    }
    v.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum::<f64>() / denominator
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Overlapping Allan deviation of a rate sampled at `rate_hz`, at averaging times of 1, 2, 4, …
/// samples up to a third of the record: `(tau_s, adev)` pairs in the rate's unit.
pub fn allan_deviation(rate: &[f64], rate_hz: f64) -> Vec<(f64, f64)> {
    let n = rate.len();
    // Phase (integrated rate) at n + 1 points.
    let mut phase = Vec::with_capacity(n + 1);
    let mut sum = 0.0;
    phase.push(0.0);
    for &r in rate {
        sum += r / rate_hz;
        phase.push(sum);
    }
    let mut out = Vec::new();
    let mut m = 1usize;
    while 3 * m <= n {
        let tau = m as f64 / rate_hz;
        let terms = phase.len() - 2 * m;
        let total: f64 = (0..terms)
            .map(|k| (phase[k + 2 * m] - 2.0 * phase[k + m] + phase[k]).powi(2))
            .sum();
        out.push((tau, (total / (2.0 * tau * tau * terms as f64)).sqrt()));
        m *= 2;
    }
    out
}

/// One activation, one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisOfActivation {
    /// Mean rate (the bias at this orientation, Earth rate included), °/s.
    pub bias_dps: f64,
    /// Standard deviation of single samples, °/s.
    pub sample_std_dps: f64,
    /// Standard deviation of the 1-s means about their activation mean, °/s.
    pub mean_spread_dps: f64,
    /// The paper's drift metric over the whole activation: max − min of the 1-s means, °/s.
    pub drift_dps: f64,
    /// Slope of the 1-s means against time (slow drift), °/s per hour.
    pub slow_drift_dps_per_h: Option<Estimate>,
    /// Slope of the 1-s means against the 1-s mean temperature within this activation, (°/s)/°C.
    pub temperature_slope: Option<Estimate>,
    /// Overlapping Allan deviation: (τ in s, σ in °/s).
    pub allan: Vec<(f64, f64)>,
}

/// One activation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Activation {
    /// Series number (the CSV import's activation, from 1).
    pub series: u32,
    /// Length, s.
    pub duration_s: f64,
    /// Mean, lowest and highest 1-s mean temperature, °C.
    pub temperature_celsius: [f64; 3],
    /// Correlation of the 1-s mean temperature with time: near ±1 means temperature and slow
    /// drift cannot be told apart within the activation.
    pub temperature_time_correlation: f64,
    /// Mean accelerometer reading X, Y, Z, g (the orientation), if recorded.
    pub accel_g: Option<[f64; 3]>,
    /// Per axis X, Y, Z.
    pub axes: [AxisOfActivation; 3],
}

/// The residual of one axis before and after a linear temperature correction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Correction {
    /// RMS of the 1-s means about their activation mean, over all activations' 1-s means, °/s.
    pub rms_before_dps: f64,
    /// The same after subtracting slope × (temperature − activation mean temperature), with the
    /// slope fitted on the other activations, °/s.
    pub rms_after_dps: f64,
    /// Mean over activations of the drift metric (max − min of the 1-s means), °/s.
    pub drift_before_dps: f64,
    /// The same after the correction, °/s.
    pub drift_after_dps: f64,
}

/// One axis over all activations.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisSummary {
    /// Axis name.
    pub axis: &'static str,
    /// Pooled within-activation slope of the 1-s mean rate against the 1-s mean temperature
    /// (each activation's means removed), (°/s)/°C. Its standard error is the OLS one inflated for
    /// the residuals' lag-1 autocorrelation: × √((1 + ρ)/(1 − ρ)).
    pub within_slope: Option<Estimate>,
    /// The OLS standard error before that inflation, (°/s)/°C.
    pub within_slope_ols_se: Option<f64>,
    /// Lag-1 autocorrelation of the within-activation residuals.
    pub residual_lag1: f64,
    /// Slope of the activation mean rates against the activation mean temperatures, (°/s)/°C;
    /// orientation and recording day change between activations too.
    pub between_slope: Option<Estimate>,
    /// Linear temperature correction, leave one activation out.
    pub correction: Option<Correction>,
    /// Lowest Allan deviation over every activation's curve at τ up to a tenth of the
    /// activation (at least ten independent averages), and its τ: (τ in s, σ in °/s).
    pub allan_minimum: Option<(f64, f64)>,
}

/// What measured data without the paper's structure can tell, per recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Characterisation {
    /// Unit id.
    pub unit_id: String,
    /// Sample rate of the recording's grid, Hz.
    pub sample_rate_hz: u32,
    /// Settings used.
    pub settings: MeasuredSettings,
    /// What the paper's method lacks here (empty: it can be fitted).
    pub obstacles: Vec<Obstacle>,
    /// Lowest and highest 1-s mean temperature over all activations, °C.
    pub temperature_range_celsius: [f64; 2],

    /// Per activation.
    pub activations: Vec<Activation>,
    /// Per axis X, Y, Z.
    pub axes: Vec<AxisSummary>,
}

/// Per-activation 1-s means: (rate per axis, temperature).
struct Means {
    rate: [Vec<f64>; 3],
    temperature: Vec<f64>,
}

fn means_of(segment: &Segment, settings: &MeasuredSettings) -> Means {
    let window = window_samples(segment, settings.mean_window_s);
    let rate = std::array::from_fn(|a| {
        block_means(segment.rate_dps[a].iter().map(|&v| f64::from(v)), window)
    });
    Means {
        rate,
        temperature: temperature_means(segment, settings),
    }
}

fn activation(segment: &Segment, means: &Means, settings: &MeasuredSettings) -> Activation {
    let fs = f64::from(segment.sample_rate_hz);
    let t = &means.temperature;
    let times: Vec<f64> = (0..t.len())
        .map(|i| (i as f64 + 0.5) * settings.mean_window_s)
        .collect();
    let correlation = {
        let (mt, mx) = (mean(t), mean(&times));
        let sxy: f64 = t.iter().zip(&times).map(|(a, b)| (a - mt) * (b - mx)).sum();
        let sxx: f64 = t.iter().map(|a| (a - mt).powi(2)).sum();
        let syy: f64 = times.iter().map(|b| (b - mx).powi(2)).sum();
        sxy / (sxx * syy).sqrt()
    };
    let accel_g = ["accel_x", "accel_y", "accel_z"]
        .iter()
        .map(|name| segment.aux.get(*name).filter(|c| !c.values.is_empty()))
        .collect::<Option<Vec<_>>>()
        .map(|channels| {
            std::array::from_fn(|a| {
                let v: Vec<f64> = channels[a].values.iter().map(|&x| f64::from(x)).collect();
                mean(&v)
            })
        });
    let axes = std::array::from_fn(|a| {
        let rate: Vec<f64> = segment.rate_dps[a].iter().map(|&v| f64::from(v)).collect();
        let bias = mean(&rate);
        let m = &means.rate[a];
        let mm = mean(m);
        AxisOfActivation {
            bias_dps: bias,
            sample_std_dps: (rate.iter().map(|v| (v - bias).powi(2)).sum::<f64>()
                / (rate.len().max(2) - 1) as f64)
                .sqrt(),
            mean_spread_dps: (m.iter().map(|v| (v - mm).powi(2)).sum::<f64>()
                / (m.len().max(2) - 1) as f64)
                .sqrt(),
            drift_dps: spread(m.iter().copied()),
            slow_drift_dps_per_h: slope(&times, m, 2).map(|(e, _)| Estimate {
                value: e.value * 3600.0,
                standard_error: e.standard_error * 3600.0,
            }),
            temperature_slope: slope(t, m, 2).map(|(e, _)| e),
            allan: allan_deviation(&rate, fs),
        }
    });
    Activation {
        series: segment.labels.series,
        duration_s: segment.len() as f64 / fs,
        temperature_celsius: [
            mean(t),
            t.iter().copied().fold(f64::INFINITY, f64::min),
            t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ],
        temperature_time_correlation: correlation,
        accel_g,
        axes,
    }
}

/// Centred copies of each activation's 1-s means of `axis` and temperature, skipping `leave`.
fn centred(all: &[Means], axis: usize, leave: Option<usize>) -> (Vec<f64>, Vec<f64>, usize) {
    let (mut x, mut y, mut groups) = (Vec::new(), Vec::new(), 0);
    for (k, m) in all.iter().enumerate() {
        if Some(k) == leave || m.temperature.is_empty() {
            continue;
        }
        groups += 1;
        let (mt, mr) = (mean(&m.temperature), mean(&m.rate[axis]));
        x.extend(m.temperature.iter().map(|t| t - mt));
        y.extend(m.rate[axis].iter().map(|r| r - mr));
    }
    (x, y, groups)
}

fn axis_summary(axis: usize, all: &[Means], activations: &[Activation]) -> AxisSummary {
    let (x, y, groups) = centred(all, axis, None);
    // The activation means are removed: one degree of freedom per activation, one for the slope.
    let pooled = slope(&x, &y, groups + 1);
    let rho = pooled.as_ref().map_or(0.0, |(_, e)| lag1(e));
    let inflation = if rho > 0.0 && rho < 1.0 {
        ((1.0 + rho) / (1.0 - rho)).sqrt()
    } else {
        1.0
    };
    let between = slope(
        &activations
            .iter()
            .map(|a| a.temperature_celsius[0])
            .collect::<Vec<_>>(),
        &activations
            .iter()
            .map(|a| a.axes[axis].bias_dps)
            .collect::<Vec<_>>(),
        2,
    )
    .map(|(e, _)| e);
    let mut before = Vec::new();
    let mut after = Vec::new();
    let mut drift = (Vec::new(), Vec::new());
    for (k, m) in all.iter().enumerate() {
        let (x, y, groups) = centred(all, axis, Some(k));
        let Some((b, _)) = slope(&x, &y, groups + 1) else {
            continue;
        };
        let (mt, mr) = (mean(&m.temperature), mean(&m.rate[axis]));
        let raw: Vec<f64> = m.rate[axis].iter().map(|r| r - mr).collect();
        let corrected: Vec<f64> = raw
            .iter()
            .zip(&m.temperature)
            .map(|(r, t)| r - b.value * (t - mt))
            .collect();
        drift.0.push(spread(raw.iter().copied()));
        drift.1.push(spread(corrected.iter().copied()));
        before.extend(raw);
        after.extend(corrected);
    }
    let correction = (!before.is_empty()).then(|| Correction {
        rms_before_dps: rms(&before),
        rms_after_dps: rms(&after),
        drift_before_dps: mean(&drift.0),
        drift_after_dps: mean(&drift.1),
    });
    let allan_minimum = activations
        .iter()
        .flat_map(|a| {
            let longest_tau = a.duration_s / 10.0;
            a.axes[axis]
                .allan
                .iter()
                .copied()
                .filter(move |(t, _)| *t <= longest_tau)
        })
        .filter(|(_, s)| s.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1));
    AxisSummary {
        axis: ["X", "Y", "Z"][axis],
        within_slope: pooled.as_ref().map(|(e, _)| Estimate {
            value: e.value,
            standard_error: e.standard_error * inflation,
        }),
        within_slope_ols_se: pooled.as_ref().map(|(e, _)| e.standard_error),
        residual_lag1: rho,
        between_slope: between,
        correction,
        allan_minimum,
    }
}

/// Characterises one unit's activations (see the module docs).
pub fn characterise(
    unit_id: &str,
    segments: &[Segment],
    settings: &MeasuredSettings,
) -> Characterisation {
    let all: Vec<Means> = segments.iter().map(|s| means_of(s, settings)).collect();
    let activations: Vec<Activation> = segments
        .iter()
        .zip(&all)
        .map(|(s, m)| activation(s, m, settings))
        .collect();
    let temperatures = all.iter().flat_map(|m| m.temperature.iter().copied());
    let range = temperatures.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], t| {
        [lo.min(t), hi.max(t)]
    });
    Characterisation {
        unit_id: unit_id.to_owned(),
        sample_rate_hz: segments.first().map_or(0, |s| s.sample_rate_hz),
        settings: *settings,
        obstacles: obstacles(segments, settings),
        temperature_range_celsius: range,
        axes: (0..3)
            .map(|a| axis_summary(a, &all, &activations))
            .collect(),
        activations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drift_recording::{SegmentLabels, SeriesKind, RAW_PER_CELSIUS};

    fn segment(
        series: u32,
        n: usize,
        rate: impl Fn(usize) -> f32,
        celsius: impl Fn(usize) -> f64,
    ) -> Segment {
        let raw: Vec<i16> = (0..n)
            .map(|i| (celsius(i) * RAW_PER_CELSIUS).round() as i16)
            .collect();
        let r: Vec<f32> = (0..n).map(&rate).collect();
        Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: 25.0,
                session_set_point_celsius: None,
                series_kind: SeriesKind::Protocol,
                series,
                repeat: 1,
                activation: 1,
                interval_min: None,
                off_before_s: None,
            },
            sample_rate_hz: 100,
            power_on_ns: 0,
            since_power_on: (0..n as u32).collect(),
            rate_dps: [r.clone(), r.clone(), r],
            temperature_raw: [raw.clone(), raw.clone(), raw],
            temperature_scale: drift_recording::TemperatureScale::default(),
            aux: Default::default(),
        }
    }

    #[test]
    fn allan_deviation_of_known_signals() {
        // A deterministic ±1 alternation: successive 1-sample means differ by 2, so σ(τ = 1 sample)
        // = √(2²/2) = √2; over 2 samples and more the alternation averages out exactly.
        let alternating: Vec<f64> = (0..4096)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let adev = allan_deviation(&alternating, 100.0);
        assert!((adev[0].0 - 0.01).abs() < 1e-12);
        assert!((adev[0].1 - 2f64.sqrt()).abs() < 1e-9, "{:?}", adev[0]);
        assert!(adev[1].1 < 1e-9, "{:?}", adev[1]);
        // A constant has zero Allan deviation; a ramp of a °/s per s has a·τ/√2.
        let ramp: Vec<f64> = (0..1000).map(|i| 0.5 * i as f64 / 100.0).collect();
        for (tau, s) in allan_deviation(&ramp, 100.0) {
            assert!((s - 0.5 * tau / 2f64.sqrt()).abs() < 1e-9, "τ {tau}: {s}");
        }
    }

    #[test]
    fn a_known_temperature_slope_is_found_and_corrected_out_of_sample() {
        // Three activations at different levels (orientation), each warming 0.5 °C over 100 s,
        // with a bias slope of 0.02 (°/s)/°C and a small alternating noise.
        let slope_true = 0.02;
        let segments: Vec<Segment> = (0..3)
            .map(|k| {
                let start = 24.0 + k as f64;
                let celsius = move |i: usize| start + 0.5 * (i as f64 / 10_000.0).sqrt();
                segment(
                    k as u32 + 1,
                    10_000,
                    move |i| {
                        (1.0 + k as f64
                            + slope_true * (celsius(i) - start)
                            + if i % 2 == 0 { 0.003 } else { -0.003 })
                            as f32
                    },
                    celsius,
                )
            })
            .collect();
        let c = characterise("U", &segments, &MeasuredSettings::default());
        let x = &c.axes[0];
        let within = x.within_slope.unwrap();
        assert!((within.value - slope_true).abs() < 2e-3, "{within:?}");
        let correction = x.correction.unwrap();
        assert!(
            correction.rms_after_dps < 0.3 * correction.rms_before_dps,
            "{correction:?}"
        );
        assert!((c.activations[2].axes[0].bias_dps - 3.0).abs() < 0.02);
        // No warm-up (0.5 °C), one ambient (2 °C span), no power cycles: all three named.
        assert_eq!(c.obstacles.len(), 3, "{:?}", c.obstacles);
        let text = NotFittable {
            unit: "U".into(),
            obstacles: c.obstacles.clone(),
        }
        .to_string();
        assert!(
            text.contains("no power-on warm-up") && text.contains("one ambient"),
            "{text}"
        );
    }

    #[test]
    fn a_warm_up_at_two_ambients_with_off_times_is_no_obstacle() {
        let mut segments: Vec<Segment> = [20.0, 30.0]
            .iter()
            .map(|&start| {
                segment(
                    1,
                    12_000,
                    |_| 0.0,
                    move |i| start + 3.0 * (i as f64 / 12_000.0),
                )
            })
            .collect();
        assert_eq!(
            obstacles(&segments, &MeasuredSettings::default()),
            vec![Obstacle::NoPowerCycles { activations: 2 }]
        );
        segments[0].labels.interval_min = Some(1.0);
        assert!(obstacles(&segments, &MeasuredSettings::default()).is_empty());
    }
}
