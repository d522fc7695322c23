//! One activation → its low-frequency drift and temperature-rise curves (the paper's `g` and the
//! temperature "excluding initial bias"), on a coarse time grid.

use drift_recording::{Segment, SegmentLabels, RAW_PER_CELSIUS};

use crate::error::FitError;
use crate::lowpass::CentredAverages;
use crate::settings::FitSettings;

/// The curves of one activation, per axis, every `grid_ms` from switch-on.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysed {
    /// The activation's labels.
    pub labels: SegmentLabels,
    /// Spacing of the curves, ms.
    pub grid_ms: u32,
    /// Raw temperature at switch-on per axis, as firmware would pass it to `power_on` (the mean over
    /// the switch-on window).
    pub switch_on_raw: [f32; 3],
    /// Switch-on temperature per axis, °C.
    pub switch_on_celsius: [f64; 3],
    /// Initial (switch-on) bias per axis, °/s.
    pub initial_bias_dps: [f64; 3],
    /// Low-frequency drift `g(t)`: low-passed rate minus the initial bias, °/s.
    pub drift_dps: [Vec<f32>; 3],
    /// Temperature rise since switch-on (low-passed), °C.
    pub rise_celsius: [Vec<f32>; 3],
}

impl Analysed {
    /// Number of grid points.
    pub fn len(&self) -> usize {
        self.drift_dps[0].len()
    }

    /// Whether there are no grid points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Time of grid point `i`, s.
    pub fn time_s(&self, i: usize) -> f64 {
        i as f64 * f64::from(self.grid_ms) / 1000.0
    }
}

/// Ordinary least-squares intercept of `y` against `x`.
fn intercept(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    if sxx <= f64::EPSILON {
        return my;
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    my - sxy / sxx * mx
}

/// Analyses one activation.
pub fn analyse(segment: &Segment, settings: &FitSettings) -> Result<Analysed, FitError> {
    let rate_hz = f64::from(segment.sample_rate_hz.max(1));
    let samples_per_ms = rate_hz / 1000.0;
    let n = segment.len();
    let initial = (settings.initial_bias_window_s * rate_hz).round() as usize;
    let switch_on =
        ((f64::from(settings.switch_on_window_ms) * samples_per_ms).round() as usize).max(1);
    let needed = initial
        .max(switch_on)
        .max((settings.first_reference_s * rate_hz).ceil() as usize + 1);
    let lengths_agree = segment.rate_dps.iter().all(|v| v.len() == n)
        && segment.temperature_raw.iter().all(|v| v.len() == n);
    if !lengths_agree {
        return Err(FitError::Inconsistent {
            unit: segment.labels.unit_id.clone(),
            series: segment.labels.series,
            activation: segment.labels.activation,
            what: "rate and temperature arrays differ in length".into(),
        });
    }
    if let Some((axis, sample)) = segment.first_missing_temperature() {
        // A calibration curve with a hole would be fitted from invented temperatures: refuse it.
        return Err(FitError::Inconsistent {
            unit: segment.labels.unit_id.clone(),
            series: segment.labels.series,
            activation: segment.labels.activation,
            what: format!(
                "axis {} temperature reading missing at sample {sample} (sensor dropout); \
                 calibration activations must be complete",
                ["X", "Y", "Z"][axis]
            ),
        });
    }
    if n < needed {
        return Err(FitError::TooShort {
            unit: segment.labels.unit_id.clone(),
            set_point: segment.labels.set_point_celsius,
            series: segment.labels.series,
            activation: segment.labels.activation,
            samples: n,
            needed,
        });
    }
    let step = ((f64::from(settings.grid_ms) * samples_per_ms).round() as usize).max(1);
    let mut out = Analysed {
        labels: segment.labels.clone(),
        grid_ms: settings.grid_ms,
        switch_on_raw: [0.0; 3],
        switch_on_celsius: [0.0; 3],
        initial_bias_dps: [0.0; 3],
        drift_dps: Default::default(),
        rise_celsius: Default::default(),
    };
    // The low-passed temperature and rate of every axis, from one pass over the samples; evaluated
    // only where they are used (the initial-bias window and the grid).
    let [t0, t1, t2] = &segment.temperature_raw;
    let [r0, r1, r2] = &segment.rate_dps;
    let samples = t0
        .iter()
        .zip(t1)
        .zip(t2)
        .zip(r0.iter().zip(r1).zip(r2))
        .map(|(((&t0, &t1), &t2), ((&r0, &r1), &r2))| {
            [
                f64::from(t0),
                f64::from(t1),
                f64::from(t2),
                f64::from(r0),
                f64::from(r1),
                f64::from(r2),
            ]
        });
    let averages = CentredAverages::new(samples, settings.lowpass_window_samples);
    for axis in 0..3 {
        let raw = &segment.temperature_raw[axis];
        let rate = &segment.rate_dps[axis];
        let on_raw = raw[..switch_on].iter().map(|&r| f64::from(r)).sum::<f64>() / switch_on as f64;
        out.switch_on_raw[axis] = on_raw as f32;
        out.switch_on_celsius[axis] = on_raw / RAW_PER_CELSIUS;
        let rise = |i: usize| (averages.at(i, axis) - on_raw) / RAW_PER_CELSIUS;
        let rate_lf = |i: usize| averages.at(i, 3 + axis);
        // The initial bias is where the rate would be at zero rise: the intercept of rate against
        // rise over the first seconds, which uses thousands of samples instead of the few
        // around t = 0.
        let rise_head: Vec<f64> = (0..initial).map(rise).collect();
        let raw_rate: Vec<f64> = rate[..initial].iter().map(|&r| f64::from(r)).collect();
        let bias0 = intercept(&rise_head, &raw_rate);
        out.initial_bias_dps[axis] = bias0;
        out.drift_dps[axis] = (0..n)
            .step_by(step)
            .map(|i| (rate_lf(i) - bias0) as f32)
            .collect();
        out.rise_celsius[axis] = (0..n).step_by(step).map(|i| rise(i) as f32).collect();
    }
    Ok(out)
}
