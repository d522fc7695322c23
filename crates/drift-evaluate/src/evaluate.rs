//! Evaluation: run fitted models through drift-core's f32 corrector (what firmware runs) over
//! activations and measure the paper's metric.
//!
//! Drift of an activation = max − min of the low-frequency component (the paper's 1-s sliding
//! average) of the corrected rate over the activation, °/s. The residual bias RMS is the RMS of the
//! same low-frequency component (the unit is static, so the true rate is zero); unlike the drift,
//! it includes the error of the initial bias.

use drift_core::{Corrector, Model, Previous, Sample, SwitchOn};
use drift_recording::{temperature_reading, Segment, SegmentLabels};

use drift_fit::fit::FittedUnit;
use drift_fit::lowpass::centred_moving_average;
use drift_fit::settings::FitSettings;

/// The models compared, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModelKind {
    /// No correction.
    Uncorrected,
    /// The paper's standard calibration.
    Standard,
    /// The least-squares polynomial (PX4/ArduPilot practice).
    ThirdOrder,
    /// The least-squares polynomial relative to the switch-on: the turn-on bias registered from
    /// the calibration, the drift after it `p(T) − p(T_on)`.
    Relative,
    /// The same form with `p` and `q` cubic, no order chosen (PX4's and ArduPilot's order,
    /// relative to the switch-on).
    RelativeCubic,
    /// The paper's modified method.
    Modified,
    /// The paper's tables with stage 3 keyed by heating history, fed what firmware would have
    /// kept of the unit's previous activation ([`kept_before`]).
    ByHistory,
    /// The recommended model: the paper's drift after switch-on with the turn-on bias fitted on
    /// every calibration activation, fed what firmware would have kept of the previous activation.
    Recommended,
    /// The paper's modified method started at the ambient the instrument measured at switch-on
    /// (a logged channel, `drift_core`'s `power_on_at_ambient`): stage 2 and the initial bias read
    /// there, not at the switch-on temperature. Evaluated only where that channel is named
    /// ([`evaluate_at`]); not in [`ModelKind::ALL`].
    AtAmbient,
}

impl ModelKind {
    /// Every model, in report order.
    pub const ALL: [ModelKind; 8] = [
        Self::Uncorrected,
        Self::Standard,
        Self::ThirdOrder,
        Self::Relative,
        Self::RelativeCubic,
        Self::Modified,
        Self::ByHistory,
        Self::Recommended,
    ];

    /// The standard baselines the paper's model is compared against: the best of them on
    /// held-out data is the headline's reference.
    pub const BASELINES: [ModelKind; 4] = [
        Self::Standard,
        Self::ThirdOrder,
        Self::Relative,
        Self::RelativeCubic,
    ];

    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Uncorrected => "uncorrected",
            Self::Standard => "standard",
            Self::ThirdOrder => "3rd-order",
            Self::Relative => "relative",
            Self::RelativeCubic => "relative-cubic",
            Self::Modified => "modified",
            Self::ByHistory => "by-history",
            Self::Recommended => "recommended",
            Self::AtAmbient => "modified-at-ambient",
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

/// The paper's drift metric of a series: max − min of its finite values (0 for none).
pub fn spread(values: impl IntoIterator<Item = f64>) -> f64 {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

/// Per axis, the paper's drift metric (max − min of the low-passed rate) and the RMS of the
/// low-passed rate, with a `window`-sample centred moving average.
pub fn metric(rates: &[Vec<f32>; 3], window: usize) -> ([f64; 3], [f64; 3]) {
    let mut drift = [0.0; 3];
    let mut rms = [0.0; 3];
    for axis in 0..3 {
        let low = centred_moving_average(&rates[axis], window);
        drift[axis] = spread(low.iter().copied());
        rms[axis] = (low.iter().map(|v| v * v).sum::<f64>() / low.len().max(1) as f64).sqrt();
    }
    (drift, rms)
}

/// Per axis, where within the activation the low-passed rate sits: its mean over each time bin
/// since switch-on (`edges_s`, s, increasing; bin `i` is `[edges_s[i], edges_s[i + 1])`) less its
/// mean over the whole activation, °/s; NaN for a bin the activation ends before. The drift metric
/// says how far the residual moves within an activation; this says when, which separates an
/// offset (no profile), a transient after switch-on, and a slow ramp.
pub fn profile(
    rates: &[Vec<f32>; 3],
    window: usize,
    rate_hz: f64,
    edges_s: &[f64],
) -> [Vec<f64>; 3] {
    std::array::from_fn(|axis| {
        let low = centred_moving_average(&rates[axis], window);
        let whole = low.iter().sum::<f64>() / low.len().max(1) as f64;
        let index = |s: f64| ((s * rate_hz).max(0.0) as usize).min(low.len());
        edges_s
            .windows(2)
            .map(|bin| {
                let part = &low[index(bin[0])..index(bin[1]).max(index(bin[0]))];
                if part.is_empty() {
                    f64::NAN
                } else {
                    part.iter().sum::<f64>() / part.len() as f64 - whole
                }
            })
            .collect()
    })
}

/// The noise floor of `activations` (one zero-drift unit's, recorded like the unit they stand
/// beside): per axis, the mean over them of [`metric`]'s drift and RMS of the uncorrected rate
/// less the unit's constant bias (its mean over every one of them). What a perfect model would
/// leave: white noise and bias instability through the 1-s window.
pub fn noise_floor(activations: &[&Segment], window_s: f64) -> [(f64, f64); 3] {
    mean_floor(&noise_floor_per_activation(activations, window_s))
}

/// The mean over activations of [`noise_floor_per_activation`]'s figures: [`noise_floor`] for a
/// caller that keeps the activations' figures too.
pub fn mean_floor(per_activation: &[[(f64, f64); 3]]) -> [(f64, f64); 3] {
    let n = per_activation.len().max(1) as f64;
    let mut sums = [(0.0, 0.0); 3];
    for per_axis in per_activation {
        for (sum, (drift, rms)) in sums.iter_mut().zip(per_axis) {
            sum.0 += drift;
            sum.1 += rms;
        }
    }
    sums.map(|(drift, rms)| (drift / n, rms / n))
}

/// [`noise_floor`] activation by activation: per activation and axis, the drift and RMS (what an
/// interval over the activations resamples, [`crate::excess`]). The low-pass is `window_s`
/// seconds of each activation's own samples.
pub fn noise_floor_per_activation(activations: &[&Segment], window_s: f64) -> Vec<[(f64, f64); 3]> {
    let offset = constant_bias(activations.iter().map(|s| mean_rate(s)));
    activations
        .iter()
        .map(|s| activation_floor(s, offset, window_s))
        .collect()
}

/// An activation's mean rate per axis, °/s: what [`constant_bias`] averages.
pub fn mean_rate(segment: &Segment) -> [f64; 3] {
    std::array::from_fn(|a| {
        segment.rate_dps[a]
            .iter()
            .map(|&v| f64::from(v))
            .sum::<f64>()
            / segment.len().max(1) as f64
    })
}

/// A zero-drift unit's constant bias per axis: the mean of its activations' [`mean_rate`]s, in
/// their order (so a caller streaming the activations gets the same bits).
pub fn constant_bias(mean_rates: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let mut sums = [0.0; 3];
    let mut n = 0usize;
    for means in mean_rates {
        for (sum, mean) in sums.iter_mut().zip(means) {
            *sum += mean;
        }
        n += 1;
    }
    sums.map(|sum| sum / n.max(1) as f64)
}

/// One activation's noise floor per axis, (drift, RMS) of its 1-s mean less `offset` (the unit's
/// [`constant_bias`]).
pub fn activation_floor(segment: &Segment, offset: [f64; 3], window_s: f64) -> [(f64, f64); 3] {
    let centred: [Vec<f32>; 3] = std::array::from_fn(|a| {
        segment.rate_dps[a]
            .iter()
            .map(|&v| (f64::from(v) - offset[a]) as f32)
            .collect()
    });
    let window = FitSettings {
        lowpass_window_s: window_s,
        ..FitSettings::default()
    }
    .lowpass_window(segment.sample_rate_hz);
    let (drift, rms) = metric(&centred, window);
    std::array::from_fn(|a| (drift[a], rms[a]))
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
    correct_segment_after(model, segment, switch_on, None)
}

/// [`correct_segment`] started with `power_on_after(previous)` when `previous` is given.
pub fn correct_segment_after<M: Model>(
    model: &M,
    segment: &Segment,
    switch_on: [f32; 3],
    previous: Option<&[Previous; 3]>,
) -> ([Vec<f32>; 3], [u16; 3]) {
    let (corrected, flags, _) =
        correct_segment_counting(model, segment, switch_on, previous, drift_core::Flags::NONE);
    (corrected, flags)
}

/// [`correct_segment_after`] started at the ambient the instrument measured at switch-on
/// (`power_on_at_ambient`, or `power_on_after_at_ambient` when `previous` is given): the paper's
/// stage 2 and initial bias read there, not at the switch-on temperature.
pub fn correct_segment_at_ambient<M: Model>(
    model: &M,
    segment: &Segment,
    switch_on: [f32; 3],
    ambient_celsius: f32,
    previous: Option<&[Previous; 3]>,
) -> ([Vec<f32>; 3], [u16; 3]) {
    let (corrected, flags, _) = correct_started(
        model,
        segment,
        switch_on,
        previous,
        Some(ambient_celsius),
        drift_core::Flags::NONE,
    );
    (corrected, flags)
}

/// [`correct_segment_after`] that also counts, per axis, the samples any of `counted` flags.
pub fn correct_segment_counting<M: Model>(
    model: &M,
    segment: &Segment,
    switch_on: [f32; 3],
    previous: Option<&[Previous; 3]>,
    counted: drift_core::Flags,
) -> ([Vec<f32>; 3], [u16; 3], [usize; 3]) {
    correct_started(model, segment, switch_on, previous, None, counted)
}

/// One activation through the corrector, started with `previous` and at `ambient_celsius` where
/// they are given, counting the samples any of `counted` flags.
fn correct_started<M: Model>(
    model: &M,
    segment: &Segment,
    switch_on: [f32; 3],
    previous: Option<&[Previous; 3]>,
    ambient_celsius: Option<f32>,
    counted: drift_core::Flags,
) -> ([Vec<f32>; 3], [u16; 3], [usize; 3]) {
    let n = segment.len();
    let mut corrected: [Vec<f32>; 3] = [
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    ];
    let mut flags = [0u16; 3];
    let mut count = [0usize; 3];
    let Ok(mut corrector) = Corrector::new(model) else {
        return (
            segment.rate_dps.clone(),
            [drift_core::Flags::MODEL_INVALID.0; 3],
            count,
        );
    };
    let started = match (previous, ambient_celsius) {
        (Some(previous), None) => corrector.power_on_after(switch_on, &mut previous.clone()),
        (None, None) => corrector.power_on(switch_on),
        (Some(previous), Some(ambient)) => {
            corrector.power_on_after_at_ambient(switch_on, ambient, &mut previous.clone())
        }
        (None, Some(ambient)) => corrector.power_on_at_ambient(switch_on, ambient),
    };
    if started.is_err() {
        return (
            segment.rate_dps.clone(),
            [drift_core::Flags::NOT_POWERED_ON.0; 3],
            count,
        );
    }
    for i in 0..n {
        let sample = sample_at(segment, i);
        let out = corrector.correct(&sample);
        for axis in 0..3 {
            corrected[axis].push(out.corrected_dps[axis]);
            flags[axis] |= out.flags[axis].0;
            count[axis] += usize::from(out.flags[axis].intersects(counted));
        }
    }
    (corrected, flags, count)
}

/// Whether firmware with a clock would know the unit cooled fully before `segment`: off at least
/// the calibration's cool-down (`independent_after_min`, the off-time after which the fit counts a
/// start as independent), by the recording's off-time.
pub fn cooled_before(segment: &Segment, settings: &FitSettings) -> bool {
    segment
        .labels
        .off_before_s
        .is_some_and(|s| s >= settings.independent_after_min * 60.0)
}

/// What firmware that keeps its history across power-off would know at each activation's
/// switch-on (for [`evaluate_after`]), in the order of `segments`: the unit's activations in order
/// of switch-on time (one unit per call), each one's ambient estimated from the one before
/// (`drift_core::SwitchOn::estimate`, as `power_on_after` does) and the previous activation's
/// last good temperature reading as its switch-off temperature. The first activation has nothing
/// kept ([`Previous::NOTHING`]). With `clock`, the firmware also knows when the unit was off
/// longer than the calibration's cool-down ([`cooled_before`]): then [`Previous::COOLED`].
pub fn kept_before(
    segments: &[&Segment],
    settings: &FitSettings,
    core: &drift_core::Settings,
    clock: bool,
) -> Vec<[Previous; 3]> {
    let mut order: Vec<usize> = (0..segments.len()).collect();
    order.sort_by_key(|&i| segments[i].power_on_ns);
    let mut kept = vec![Previous::NOTHING; segments.len()];
    let mut previous = Previous::NOTHING;
    for i in order {
        if clock && cooled_before(segments[i], settings) {
            previous = Previous::COOLED;
        }
        kept[i] = previous;
        previous = kept_after(&previous, segments[i], settings, core);
    }
    kept
}

/// What firmware keeps after `segment` for the next switch-on, having kept `previous` before it:
/// per axis the ambient `power_on_after` estimates (`drift_core::SwitchOn::estimate`) and the
/// last good temperature reading, as the corrector's `keep` records it (the switch-on reading if
/// none followed).
pub fn kept_after(
    previous: &[Previous; 3],
    segment: &Segment,
    settings: &FitSettings,
    core: &drift_core::Settings,
) -> [Previous; 3] {
    let switch_on = switch_on_raw(segment, settings);
    std::array::from_fn(|axis| {
        let estimate = SwitchOn::estimate(core.celsius(switch_on[axis]), Some(previous[axis]));
        let last = segment.temperature_raw[axis]
            .iter()
            .rev()
            .map(|&r| temperature_reading(r))
            .find(|r| r.is_finite())
            .unwrap_or(switch_on[axis]);
        Previous {
            ambient_celsius: estimate.ambient_celsius,
            switch_off_celsius: core.celsius(last),
        }
    })
}

/// Evaluates every model on one activation, with nothing kept of the previous one (the
/// history-keyed model then takes a cold start, flagged).
pub fn evaluate(
    fitted: &FittedUnit,
    segment: &Segment,
    settings: &FitSettings,
) -> ActivationResult {
    evaluate_after(fitted, segment, settings, &Previous::NOTHING)
}

/// Evaluates every model on one activation; the history-keyed model starts with `previous`
/// ([`kept_before`]).
pub fn evaluate_after(
    fitted: &FittedUnit,
    segment: &Segment,
    settings: &FitSettings,
    previous: &[Previous; 3],
) -> ActivationResult {
    evaluate_at(fitted, segment, settings, previous, None)
}

/// [`evaluate_after`], and with `ambient_celsius` (the ambient the instrument measured at
/// switch-on, °C) also the paper's tables started there ([`ModelKind::AtAmbient`], after every
/// model of [`ModelKind::ALL`]).
pub fn evaluate_at(
    fitted: &FittedUnit,
    segment: &Segment,
    settings: &FitSettings,
    previous: &[Previous; 3],
    ambient_celsius: Option<f32>,
) -> ActivationResult {
    let window = settings.lowpass_window(segment.sample_rate_hz);
    let switch_on = switch_on_raw(segment, settings);
    let at_ambient = ambient_celsius.map(|_| ModelKind::AtAmbient);
    let models = ModelKind::ALL
        .iter()
        .chain(&at_ambient)
        .map(|&model| {
            let (rates, flags) = match model {
                ModelKind::Uncorrected => (segment.rate_dps.clone(), [0; 3]),
                ModelKind::Standard => correct_segment(&fitted.standard, segment, switch_on),
                ModelKind::ThirdOrder => correct_segment(&fitted.third_order, segment, switch_on),
                ModelKind::Relative => correct_segment(&fitted.relative, segment, switch_on),
                ModelKind::RelativeCubic => {
                    correct_segment(&fitted.relative_cubic, segment, switch_on)
                }
                ModelKind::Modified => correct_segment(&fitted.modified, segment, switch_on),
                ModelKind::ByHistory => {
                    correct_segment_after(&fitted.by_history, segment, switch_on, Some(previous))
                }
                ModelKind::Recommended => {
                    correct_segment_after(&fitted.recommended, segment, switch_on, Some(previous))
                }
                ModelKind::AtAmbient => correct_segment_at_ambient(
                    &fitted.modified,
                    segment,
                    switch_on,
                    ambient_celsius.unwrap_or(f32::NAN),
                    None,
                ),
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

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use drift_recording::{SegmentLabels, SeriesKind};

    use super::*;

    /// A step 10 s after switch-on, sampled at 10 Hz for 30 s, unfiltered: the bins read the step
    /// against the activation's mean, and a bin past the end is NaN.
    #[test]
    fn a_profile_places_a_step_in_its_bin() {
        let step: Vec<f32> = (0..300).map(|i| if i < 100 { 0.0 } else { 3.0 }).collect();
        let rates = [step.clone(), vec![1.0; 300], step];
        let [x, y, _] = profile(&rates, 1, 10.0, &[0.0, 10.0, 30.0, 60.0]);
        // Mean 2.0: the first 10 s stand 2 below it, the next 20 s 1 above.
        assert_eq!(x[..2], [-2.0, 1.0]);
        assert!(x[2].is_nan(), "{x:?}");
        assert_eq!(y[..2], [0.0, 0.0], "a constant has no profile");
    }

    /// An activation switched on at `power_on_s` after `off_before_s` off, its temperature
    /// readings going from `on` to `off` °C (200 raw units per °C).
    fn activation(power_on_s: u64, off_before_s: f64, on: f64, off: f64) -> Segment {
        let raw = |c: f64| (c * 200.0).round() as i16;
        let temperatures = vec![raw(on), raw((on + off) / 2.0), raw(off)];
        Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: 30.0,
                session_set_point_celsius: None,
                series_kind: SeriesKind::Protocol,
                series: 1,
                repeat: 1,
                activation: 1,
                interval_min: None,
                off_before_s: Some(off_before_s),
            },
            sample_rate_hz: 1000,
            power_on_ns: power_on_s * 1_000_000_000,
            since_power_on: vec![0, 1, 2],
            rate_dps: [vec![0.0; 3], vec![0.0; 3], vec![0.0; 3]],
            temperature_raw: [0, 1, 2].map(|_| temperatures.clone()),
            temperature_scale: drift_recording::TemperatureScale::default(),
            aux: BTreeMap::new(),
        }
    }

    #[test]
    fn the_noise_floor_takes_out_the_units_constant_bias_only() {
        // Two activations of a zero-drift unit: a constant 0.5 °/s bias on every axis, and on X
        // one activation 0.01 °/s above the other (what differs between activations stays).
        let mut first = activation(0, 3600.0, 30.0, 30.0);
        let mut second = activation(400, 3600.0, 30.0, 30.0);
        for axis in 0..3 {
            first.rate_dps[axis] = vec![0.5; 3];
            second.rate_dps[axis] = vec![0.5; 3];
        }
        second.rate_dps[0] = vec![0.51; 3];
        let floor = noise_floor(&[&first, &second], 0.001);
        // X: each activation is 0.005 °/s off the unit's mean, flat within itself.
        assert!((floor[0].1 - 0.005).abs() < 1e-6, "{floor:?}");
        assert!(floor[0].0.abs() < 1e-9, "{floor:?}");
        // Y and Z: nothing but the bias, so nothing is left.
        for (drift, rms) in &floor[1..] {
            assert!(drift.abs() < 1e-9 && rms.abs() < 1e-6, "{floor:?}");
        }
    }

    #[test]
    fn what_firmware_keeps_follows_the_units_life_in_time_order() {
        let settings = FitSettings {
            switch_on_window_ms: 1,
            ..FitSettings::default()
        };
        let core = drift_core::Settings::default();
        // Given out of order: the chain follows switch-on time.
        let cold = activation(0, 3600.0, 30.0, 34.0);
        let warm = activation(400, 60.0, 32.0, 35.0);
        let rose = activation(800, 60.0, 36.0, 38.0);
        // An hour off while the ambient rose to 37 °C, still below the last switch-off (38 °C).
        let soaked = activation(9000, 3600.0, 37.0, 39.0);
        let segments = [&warm, &soaked, &cold, &rose];
        let without_clock = kept_before(&segments, &settings, &core, false);
        let with_clock = kept_before(&segments, &settings, &core, true);
        let ambient = |p: &[Previous; 3]| p[0].ambient_celsius;
        let off = |p: &[Previous; 3]| p[0].switch_off_celsius;
        // The first activation in time: nothing kept, or cooled by the clock.
        assert!(ambient(&without_clock[2]).is_nan() && off(&without_clock[2]).is_nan());
        assert_eq!(off(&with_clock[2]), f32::NEG_INFINITY);
        // After the cold start: its ambient (its switch-on) and its last reading.
        assert_eq!((ambient(&with_clock[0]), off(&with_clock[0])), (30.0, 34.0));
        // The warm start keeps the ambient (residual heat 2 °C).
        assert_eq!((ambient(&with_clock[3]), off(&with_clock[3])), (30.0, 35.0));
        // Switched on above its last switch-off temperature: the ambient rose to 36 °C.
        assert_eq!(
            (ambient(&without_clock[1]), off(&without_clock[1])),
            (36.0, 38.0)
        );
        // Before the soaked start the clock says the unit cooled: a cold start at 37 °C. Without
        // it the 1 °C the ambient rose reads as residual heat on the kept 36 °C ambient.
        assert_eq!(off(&with_clock[1]), f32::NEG_INFINITY);
        let start = |kept: &[Previous; 3]| SwitchOn::estimate(37.0, Some(kept[0]));
        assert_eq!(
            (
                start(&with_clock[1]).ambient_celsius,
                start(&with_clock[1]).residual_heat_celsius
            ),
            (37.0, 0.0)
        );
        assert!(start(&with_clock[1]).known);
        assert_eq!(
            (
                start(&without_clock[1]).ambient_celsius,
                start(&without_clock[1]).residual_heat_celsius
            ),
            (36.0, 1.0)
        );
    }
}
