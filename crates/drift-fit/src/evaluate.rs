//! Evaluation: run fitted models through drift-core's f32 corrector (what firmware runs) over
//! activations and measure the paper's metric.
//!
//! Drift of an activation = max − min of the low-frequency component (the paper's 1-s sliding
//! average) of the corrected rate over the activation, °/s. The residual bias RMS is the RMS of the
//! same low-frequency component (the unit is static, so the true rate is zero); unlike the drift,
//! it includes the error of the initial bias.

use drift_core::{Corrector, Model, Sample};
use drift_recording::{temperature_reading, Segment, SegmentLabels};

use crate::fit::FittedUnit;
use crate::lowpass::centred_moving_average;
use crate::settings::FitSettings;

/// The models compared, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModelKind {
    /// No correction.
    Uncorrected,
    /// The paper's standard calibration.
    Standard,
    /// The least-squares polynomial (PX4/ArduPilot practice).
    ThirdOrder,
    /// The paper's modified method.
    Modified,
}

impl ModelKind {
    /// Every model, in report order.
    pub const ALL: [ModelKind; 4] = [
        Self::Uncorrected,
        Self::Standard,
        Self::ThirdOrder,
        Self::Modified,
    ];

    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Uncorrected => "uncorrected",
            Self::Standard => "standard",
            Self::ThirdOrder => "3rd-order",
            Self::Modified => "modified",
        }
    }
}

/// One activation's result for one model.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelResult {
    /// Which model.
    pub model: ModelKind,
    /// Drift (max − min of the low-frequency component) per axis, °/s.
    pub drift_dps: [f64; 3],
    /// RMS of the low-frequency component per axis, °/s.
    pub residual_rms_dps: [f64; 3],
    /// Union of the corrector's flags over the activation, per axis.
    pub flags: [u16; 3],
}

/// One activation's results for every model.
#[derive(Debug, Clone, PartialEq)]
pub struct ActivationResult {
    /// The activation's labels.
    pub labels: SegmentLabels,
    /// One entry per model, in [`ModelKind::ALL`] order.
    pub models: Vec<ModelResult>,
}

/// Per axis, the paper's drift metric (max − min of the low-passed rate) and the RMS of the
/// low-passed rate, with a `window`-sample centred moving average.
pub fn metric(rates: &[Vec<f32>; 3], window: usize) -> ([f64; 3], [f64; 3]) {
    let mut drift = [0.0; 3];
    let mut rms = [0.0; 3];
    for axis in 0..3 {
        let low = centred_moving_average(&rates[axis], window);
        let (lo, hi) = low
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        drift[axis] = hi - lo;
        rms[axis] = (low.iter().map(|v| v * v).sum::<f64>() / low.len().max(1) as f64).sqrt();
    }
    (drift, rms)
}

/// The switch-on reading firmware passes to `power_on`: the mean raw temperature over the first
/// `switch_on_window_ms`.
pub fn switch_on_raw(segment: &Segment, settings: &FitSettings) -> [f32; 3] {
    let n = ((f64::from(settings.switch_on_window_ms) * f64::from(segment.sample_rate_hz) / 1000.0)
        .round() as usize)
        .clamp(1, segment.len().max(1));
    segment.temperature_raw.clone().map(|raw| {
        // Missing readings (dropouts) are left out of the mean; a window without any reading
        // gives NaN, which `power_on` refuses: the activation then passes through, flagged.
        let head = raw[..n.min(raw.len())]
            .iter()
            .map(|&r| temperature_reading(r))
            .filter(|r| r.is_finite());
        let (sum, count) = head.fold((0.0, 0usize), |(s, c), r| (s + f64::from(r), c + 1));
        if count == 0 {
            f32::NAN
        } else {
            (sum / count as f64) as f32
        }
    })
}

/// Whether `model` switches on inside its calibrated ambient range on every axis for this
/// switch-on reading (no [`drift_core::Flags::AMBIENT_OUT_OF_RANGE`]). Outside it the model clamps
/// the ambient by design (a documented, flagged degradation), so such activations' residuals mix
/// that clamp with whatever else is left.
pub fn within_ambient_range<M: Model>(model: &M, switch_on: [f32; 3]) -> bool {
    let Ok(mut corrector) = Corrector::new(model) else {
        return false;
    };
    corrector.power_on(switch_on).is_ok_and(|flags| {
        flags
            .iter()
            .all(|f| !f.intersects(drift_core::Flags::AMBIENT_OUT_OF_RANGE))
    })
}

/// Sample `i` of `segment` as the firmware sees it: time in ms, rates, temperature readings (a
/// dropout reads as NaN).
pub fn sample_at(segment: &Segment, i: usize) -> Sample {
    let rate_hz = u64::from(segment.sample_rate_hz.max(1));
    Sample {
        since_power_on_ms: (u64::from(segment.since_power_on[i]) * 1000 / rate_hz) as u32,
        rate_dps: [0, 1, 2].map(|a| segment.rate_dps[a][i]),
        temperature_raw: [0, 1, 2].map(|a| temperature_reading(segment.temperature_raw[a][i])),
    }
}

/// Corrects a whole activation with one model; returns the corrected rates and flag unions.
pub fn correct_segment<M: Model>(
    model: &M,
    segment: &Segment,
    switch_on: [f32; 3],
) -> ([Vec<f32>; 3], [u16; 3]) {
    let n = segment.len();
    let mut corrected: [Vec<f32>; 3] = [
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    ];
    let mut flags = [0u16; 3];
    let Ok(mut corrector) = Corrector::new(model) else {
        return (
            segment.rate_dps.clone(),
            [drift_core::Flags::MODEL_INVALID.0; 3],
        );
    };
    if corrector.power_on(switch_on).is_err() {
        return (
            segment.rate_dps.clone(),
            [drift_core::Flags::NOT_POWERED_ON.0; 3],
        );
    }
    for i in 0..n {
        let sample = sample_at(segment, i);
        let out = corrector.correct(&sample);
        for axis in 0..3 {
            corrected[axis].push(out.corrected_dps[axis]);
            flags[axis] |= out.flags[axis].0;
        }
    }
    (corrected, flags)
}

/// Evaluates every model on one activation.
pub fn evaluate(
    fitted: &FittedUnit,
    segment: &Segment,
    settings: &FitSettings,
) -> ActivationResult {
    let window = settings.lowpass_window_samples;
    let switch_on = switch_on_raw(segment, settings);
    let models = ModelKind::ALL
        .iter()
        .map(|&model| {
            let (rates, flags) = match model {
                ModelKind::Uncorrected => (segment.rate_dps.clone(), [0; 3]),
                ModelKind::Standard => correct_segment(&fitted.standard, segment, switch_on),
                ModelKind::ThirdOrder => correct_segment(&fitted.third_order, segment, switch_on),
                ModelKind::Modified => correct_segment(&fitted.modified, segment, switch_on),
            };
            let (drift_dps, residual_rms_dps) = metric(&rates, window);
            ModelResult {
                model,
                drift_dps,
                residual_rms_dps,
                flags,
            }
        })
        .collect();
    ActivationResult {
        labels: segment.labels.clone(),
        models,
    }
}
