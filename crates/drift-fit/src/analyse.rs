//! One activation → its low-frequency drift and temperature-rise curves (the paper's `g` and the
//! temperature "excluding initial bias"), on a coarse time grid.

use drift_recording::{Segment, SegmentLabels, TemperatureScale};

use crate::error::FitError;
use crate::settings::FitSettings;
use crate::windows::Windows;

/// The curves of one activation, per axis, every `grid_ms` from switch-on.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysed {
    /// The activation's labels.
    pub labels: SegmentLabels,
    /// Spacing of the curves, ms: the settings' grid, or the smallest multiple of it that is a
    /// whole number of samples at the activation's rate ([`FitSettings::grid_at`]).
    pub grid_ms: u32,
    /// The activation's sample rate, Hz: the fitted tables state it for firmware to check.
    pub sample_rate_hz: u32,
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
    /// The sensor scale of the activation's raw temperatures (`switch_on_raw`): the fitted
    /// tables convert raw readings with it.
    pub temperature_scale: TemperatureScale,
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
///
/// The four sums in two loops of two (independent chains that overlap), each accumulated in the
/// data's order from −0.0 as `Iterator::sum` does.
fn intercept(x: &[f64], y: &[f32]) -> f64 {
    let n = x.len() as f64;
    let (mut sx, mut sy) = (-0.0_f64, -0.0_f64);
    for (&a, &b) in x.iter().zip(y) {
        sx += a;
        sy += f64::from(b);
    }
    let (mx, my) = (sx / n, sy / n);
    let (mut sxx, mut sxy) = (-0.0_f64, -0.0_f64);
    for (&a, &b) in x.iter().zip(y) {
        sxx += (a - mx).powi(2);
        sxy += (a - mx) * (f64::from(b) - my);
    }
    if sxx <= f64::EPSILON {
        return my;
    }
    my - sxy / sxx * mx
}

/// The running sums of the raw temperatures of every axis at `windows`' records.
///
/// Integer readings add exactly in i64, and the f64 running sum of the same readings is exact too
/// (every partial sum is an integer far below 2^53), so the totals are the f64 running sums' bits,
/// without a conversion per reading or a chain of f64 additions.
fn temperature_records(raw: &[Vec<i16>; 3], windows: &Windows) -> [Vec<f64>; 3] {
    let mut records: [Vec<f64>; 3] =
        std::array::from_fn(|_| Vec::with_capacity(windows.record_count()));
    let mut totals = [0_i64; 3];
    let mut added = 0;
    for position in windows.records() {
        for (total, readings) in totals.iter_mut().zip(raw) {
            *total += readings[added..position]
                .iter()
                .map(|&r| i64::from(r))
                .sum::<i64>();
        }
        added = position;
        for (record, &total) in records.iter_mut().zip(&totals) {
            record.push(total as f64);
        }
    }
    records
}

/// The running sums of the six channels: exact integer sums of the raw temperatures, f64 sums of
/// the rates, each in sample order.
#[derive(Clone, Copy, Default)]
struct Sums {
    temperatures: [i64; 3],
    rates: [f64; 3],
}

impl Sums {
    /// Adds the samples of `range` of every channel, in order.
    #[inline(always)]
    fn add(&mut self, segment: &Segment, range: std::ops::Range<usize>) {
        let [t0, t1, t2] = &segment.temperature_raw;
        let [r0, r1, r2] = &segment.rate_dps;
        let (Some(t0), Some(t1), Some(t2), Some(r0), Some(r1), Some(r2)) = (
            t0.get(range.clone()),
            t1.get(range.clone()),
            t2.get(range.clone()),
            r0.get(range.clone()),
            r1.get(range.clone()),
            r2.get(range),
        ) else {
            return;
        };
        self.add_slices([t0, t1, t2], [r0, r1, r2]);
    }

    /// One loop over the six channels: the three chains of f64 additions (the rates) overlap,
    /// and the integer additions (exact, see `temperature_records`) hide in their latency.
    #[inline(always)]
    fn add_slices(&mut self, [t0, t1, t2]: [&[i16]; 3], [r0, r1, r2]: [&[f32]; 3]) {
        let [mut i0, mut i1, mut i2] = self.temperatures;
        let [mut s0, mut s1, mut s2] = self.rates;
        let temperatures = t0.iter().zip(t1).zip(t2);
        let rates = r0.iter().zip(r1).zip(r2);
        for (((&a, &b), &c), ((&x, &y), &z)) in temperatures.zip(rates) {
            i0 += i64::from(a);
            i1 += i64::from(b);
            i2 += i64::from(c);
            s0 += f64::from(x);
            s1 += f64::from(y);
            s2 += f64::from(z);
        }
        self.temperatures = [i0, i1, i2];
        self.rates = [s0, s1, s2];
    }

    /// The sums as recorded: temperatures, then rates.
    fn values(&self) -> [f64; 6] {
        let [i0, i1, i2] = self.temperatures;
        let [s0, s1, s2] = self.rates;
        [i0 as f64, i1 as f64, i2 as f64, s0, s1, s2]
    }
}

/// The running sums of every channel (raw temperatures, then rates, per axis) at `windows'`
/// records, from one pass over the samples.
///
/// Between two lattice points (10 samples for the defaults) the six channels are added as
/// `chunks_exact` of the lattice spacing: one step of six zipped chunk iterators per record
/// instead of six range checks (the same additions in the same order: the same bits).
fn running_sums(segment: &Segment, windows: &Windows) -> [Vec<f64>; 6] {
    let count = windows.record_count();
    let mut records: [Vec<f64>; 6] = std::array::from_fn(|_| Vec::with_capacity(count));
    if count == 0 {
        return records;
    }
    let (first, spacing, points, last) = windows.lattice();
    let mut sums = Sums::default();
    let record = |sums: &Sums, records: &mut [Vec<f64>; 6]| {
        for (record, value) in records.iter_mut().zip(sums.values()) {
            record.push(value);
        }
    };
    record(&sums, &mut records);
    let mut added = 0;
    if points > 0 {
        sums.add(segment, 0..first);
        record(&sums, &mut records);
        let end = first + (points - 1) * spacing;
        let [t0, t1, t2] = &segment.temperature_raw;
        let [r0, r1, r2] = &segment.rate_dps;
        let temperatures = (t0[first..end].chunks_exact(spacing))
            .zip(t1[first..end].chunks_exact(spacing))
            .zip(t2[first..end].chunks_exact(spacing));
        let rates = (r0[first..end].chunks_exact(spacing))
            .zip(r1[first..end].chunks_exact(spacing))
            .zip(r2[first..end].chunks_exact(spacing));
        for (((a, b), c), ((x, y), z)) in temperatures.zip(rates) {
            sums.add_slices([a, b, c], [x, y, z]);
            record(&sums, &mut records);
        }
        added = end;
    }
    sums.add(segment, added..last);
    record(&sums, &mut records);
    records
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
    let (step, grid_ms) = settings.grid_at(segment.sample_rate_hz);
    let window = settings.lowpass_window(segment.sample_rate_hz);
    let mut out = Analysed {
        labels: segment.labels.clone(),
        grid_ms,
        sample_rate_hz: segment.sample_rate_hz,
        switch_on_raw: [0.0; 3],
        switch_on_celsius: [0.0; 3],
        initial_bias_dps: [0.0; 3],
        drift_dps: Default::default(),
        rise_celsius: Default::default(),
        temperature_scale: segment.temperature_scale,
    };
    let raw = &segment.temperature_raw;
    let scale = segment.temperature_scale;
    let mut on_raw = [0.0; 3];
    for axis in 0..3 {
        on_raw[axis] = raw[axis][..switch_on]
            .iter()
            .map(|&r| f64::from(r))
            .sum::<f64>()
            / switch_on as f64;
        out.switch_on_raw[axis] = on_raw[axis] as f32;
        out.switch_on_celsius[axis] = scale.celsius(on_raw[axis]);
    }
    // The initial bias is where the rate would be at zero rise: the intercept of rate against
    // rise over the first seconds, which uses thousands of samples instead of the few around
    // t = 0. Its low-passed temperatures (every sample's) come from a short pass of their own.
    let head = Windows::new(n, window, (initial, 1));
    let records = temperature_records(raw, &head);
    for axis in 0..3 {
        let on_raw = on_raw[axis];
        let rise_head = head.averages(&records[axis], move |t| {
            scale.celsius_difference(t - on_raw)
        });
        out.initial_bias_dps[axis] = intercept(&rise_head, &segment.rate_dps[axis][..initial]);
    }
    // Every channel's low-pass on the grid, from one pass over the samples.
    let grid = Windows::new(n, window, (n, step));
    let records = running_sums(segment, &grid);
    for axis in 0..3 {
        let (on_raw, bias) = (on_raw[axis], out.initial_bias_dps[axis]);
        out.rise_celsius[axis] = grid.averages(&records[axis], move |t| {
            scale.celsius_difference(t - on_raw) as f32
        });
        out.drift_dps[axis] = grid.averages(&records[3 + axis], move |rate| (rate - bias) as f32);
    }
    Ok(out)
}
