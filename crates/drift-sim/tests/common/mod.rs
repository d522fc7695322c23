//! Shared helpers: small campaigns and the paper's low-frequency analysis of a segment.
#![allow(dead_code)]

use drift_sim::{Campaign, Segment};

/// One unit at +30 °C, the paper's protocol with the given intervals and repeats.
pub fn protocol_campaign(intervals_min: &[f64], repeats: u32, noise_scale: f64) -> Campaign {
    let mut c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        noise_scale,
        ..Campaign::default()
    };
    let p = c
        .protocol
        .as_mut()
        .expect("default campaign has a protocol");
    p.intervals_min = intervals_min.to_vec();
    p.repeats = repeats;
    c
}

/// Mean of samples `[from, to)`.
pub fn mean_f32(v: &[f32], from: usize, to: usize) -> f64 {
    v[from..to].iter().map(|&x| f64::from(x)).sum::<f64>() / (to - from) as f64
}

/// Mean of raw temperature `[from, to)` in °C.
pub fn mean_celsius(v: &[i16], from: usize, to: usize) -> f64 {
    v[from..to].iter().map(|&x| f64::from(x)).sum::<f64>() / (to - from) as f64 / 200.0
}

/// The paper's quantities for one activation and axis, from the recording only.
#[derive(Debug, Clone, Copy)]
pub struct Curves {
    /// Sensor temperature at switch-on (°C), mean of the first 0.5 s.
    pub t0: f64,
    /// Sensor temperature at the end (°C), mean of the last 0.5 s.
    pub t_end: f64,
}

/// Start-of-activation reference window: 0.5 s (the rise in it is ~0.05 °C).
pub const START_WINDOW: usize = 500;
/// The paper's low-frequency window: 1 s at 1000 Hz.
pub const LF_WINDOW: usize = 1000;

/// `g(t)`: 1-s moving average of the rate centred on sample `at`, minus the initial bias
/// (mean of the first 0.5 s).
pub fn drift(seg: &Segment, axis: usize, at: usize) -> f64 {
    let r = &seg.rate_dps[axis];
    let at = at.clamp(LF_WINDOW / 2, seg.len() - LF_WINDOW / 2);
    mean_f32(r, at - LF_WINDOW / 2, at + LF_WINDOW / 2) - mean_f32(r, 0, START_WINDOW)
}

/// `rise(t)`: 1-s average of the sensor temperature centred on `at` minus its switch-on value.
pub fn rise(seg: &Segment, axis: usize, at: usize) -> f64 {
    let t = &seg.temperature_raw[axis];
    let at = at.clamp(LF_WINDOW / 2, seg.len() - LF_WINDOW / 2);
    mean_celsius(t, at - LF_WINDOW / 2, at + LF_WINDOW / 2) - mean_celsius(t, 0, START_WINDOW)
}

/// Switch-on and end temperatures.
pub fn curves(seg: &Segment, axis: usize) -> Curves {
    let t = &seg.temperature_raw[axis];
    let n = seg.len();
    Curves {
        t0: mean_celsius(t, 0, START_WINDOW),
        t_end: mean_celsius(t, n - START_WINDOW, n),
    }
}

/// Pearson correlation.
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}
