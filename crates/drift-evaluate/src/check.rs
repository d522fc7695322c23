//! Is a stored calibration still valid? The tables a unit carries (its firmware image) are run
//! through drift-core's corrector over new recordings of the unit held static, and what is left
//! is held against limits the bench sets: how much drift may remain, how large the residual bias
//! may be, how much of the drift the tables must remove. Users of thermal calibration ask for a
//! check rather than a belief (PX4 PR #17300); ageing, a unit swapped for another, or tables
//! flashed to the wrong unit all show here.
//!
//! One pass, recording by recording: [`UnitCheck::add`] corrects one activation and keeps only its
//! figures, so a long campaign is checked in the memory of one recording.

use drift_core::{Envelope, Flags, Model, Previous, Term};
use drift_recording::{Segment, SegmentLabels};

use crate::evaluate::{cooled_before, correct_segment_counting, kept_after, metric, switch_on_raw};
use drift_fit::settings::FitSettings;

/// What a calibration must still achieve on the recordings checked. Every figure is a mean over
/// the unit's activations (the paper's metric, 1-s low-pass), per axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    /// Most drift (max − min of the 1-s low-passed corrected rate) left per activation, °/s.
    /// Default 0.005: the paper's Table after its modified calibration is 0.004–0.006 °/s.
    pub max_drift_dps: f64,
    /// Largest RMS of the 1-s low-passed corrected rate, °/s: the residual bias, including the
    /// switch-on bias the tables predict (which ageing moves) and the turn-on repeatability.
    /// Default 0.02: above the 0.006–0.014 a freshly fitted simulated unit leaves on its own data
    /// (seed 5, `gyrodrift check` in docs/fitting.md), below what another unit's tables leave.
    pub max_residual_rms_dps: f64,
    /// Smallest share of the uncorrected drift the tables must remove (0…1). Default 0.5.
    pub min_removed: f64,
}

impl Limits {
    /// The first limit that means nothing (negative, NaN or infinite; a share removed above 1,
    /// which no correction can meet), as (field name, value); [`Limits::requirement`] says what
    /// the field must be.
    pub fn invalid(&self) -> Option<(&'static str, f64)> {
        [
            ("max_drift_dps", self.max_drift_dps),
            ("max_residual_rms_dps", self.max_residual_rms_dps),
            ("min_removed", self.min_removed),
        ]
        .into_iter()
        .find(|(field, value)| {
            !value.is_finite() || *value < 0.0 || (*field == "min_removed" && *value > 1.0)
        })
    }

    /// What a valid value of `field` is, in words.
    pub fn requirement(field: &str) -> &'static str {
        if field == "min_removed" {
            "a share 0…1 (0.5 = half the uncorrected drift)"
        } else {
            "a finite number ≥ 0"
        }
    }
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_drift_dps: 0.005,
            max_residual_rms_dps: 0.02,
            min_removed: 0.5,
        }
    }
}

/// Flags of faults in the recording or the tables (the corrector held its last good drift).
pub const FAULT_FLAGS: Flags = Flags(
    Flags::TEMPERATURE_INVALID.0
        | Flags::TEMPERATURE_STUCK.0
        | Flags::RATE_INVALID.0
        | Flags::NOT_POWERED_ON.0
        | Flags::MODEL_INVALID.0
        | Flags::EXTENSION_INPUT_INVALID.0,
);

/// One activation as checked.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CheckedActivation {
    /// The activation's labels.
    pub labels: SegmentLabels,
    /// Drift of the uncorrected rate per axis, °/s.
    pub uncorrected_drift_dps: [f64; 3],
    /// Drift of the corrected rate per axis, °/s.
    pub corrected_drift_dps: [f64; 3],
    /// RMS of the 1-s low-passed corrected rate per axis, °/s.
    pub residual_rms_dps: [f64; 3],
    /// Union of the corrector's flags over the activation, per axis.
    pub flags: [u16; 3],
    /// Samples in the activation.
    pub samples: usize,
    /// Per axis, samples the corrector flagged outside the calibrated envelope
    /// ([`Envelope::FLAGS`]).
    pub outside_envelope_samples: [usize; 3],
}

/// The verdict for one axis of one unit.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisVerdict {
    /// 0 = X, 1 = Y, 2 = Z.
    pub axis: usize,
    /// Activations checked.
    pub activations: usize,
    /// Mean drift of the uncorrected rate, °/s.
    pub uncorrected_drift_dps: f64,
    /// Mean drift left after correction, °/s.
    pub corrected_drift_dps: f64,
    /// Largest drift left in one activation, °/s.
    pub worst_drift_dps: f64,
    /// RMS over activations of the residual RMS, °/s.
    pub residual_rms_dps: f64,
    /// Share of the uncorrected drift removed (1 − corrected / uncorrected).
    pub removed: f64,
    /// Activations that switched on outside the calibrated ambients (clamped, as documented): a
    /// check there measures the envelope as much as the tables.
    pub ambient_out_of_range: usize,
    /// Activations whose rise left the stored curves' span (clamped).
    pub rise_out_of_span: usize,
    /// Activations that ran past the last reference time (`k` held): longer than calibrated.
    pub past_last_reference: usize,
    /// Tables keyed by history: activations that started with nothing kept of the previous one
    /// or with a residual heat beyond the stored histories (a cold start was taken).
    pub history_unknown_or_out_of_span: usize,
    /// Activations the corrector flagged outside the calibrated envelope ([`Envelope::FLAGS`]:
    /// the switch-on temperature or residual heat beyond the calibration's) on some sample.
    pub outside_envelope: usize,
    /// Samples checked.
    pub samples: usize,
    /// Of them, flagged outside the calibrated envelope.
    pub outside_envelope_samples: usize,
    /// Activations with a fault flag (sensor or tables).
    pub faulty: usize,
    /// Why the axis fails the limits; empty when it passes.
    pub failures: Vec<String>,
}

impl AxisVerdict {
    /// Whether the axis meets every limit.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

/// Accumulates one unit's activations against the model it carries.
pub struct UnitCheck<M: Model> {
    unit_id: String,
    model: M,
    settings: FitSettings,
    activations: Vec<CheckedActivation>,
    /// What the unit's firmware keeps across power-off, after the last activation added.
    previous: [Previous; 3],
}

/// A model the check cannot run: its extended model reads an auxiliary input, and neither the
/// model nor the recording says which recorded channel the firmware passes as that input.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("the extended model reads auxiliary input {input}; a stored model does not say which recorded channel the firmware passes as that input, so it cannot be checked on recordings")]
pub struct ReadsAuxiliaryInput {
    /// The input's index.
    pub input: u8,
}

impl<M: Model> UnitCheck<M> {
    /// A check of `unit_id` against `model` (the tables the unit carries). `settings` gives the
    /// switch-on window and the low-pass, as the fit used them.
    pub fn new(
        unit_id: &str,
        model: M,
        settings: &FitSettings,
    ) -> Result<Self, ReadsAuxiliaryInput> {
        for term in &model.extension().terms {
            if let Term::Aux { input, .. } = term.term {
                return Err(ReadsAuxiliaryInput { input });
            }
        }
        Ok(Self {
            unit_id: unit_id.to_owned(),
            model,
            settings: settings.clone(),
            activations: Vec::new(),
            previous: Previous::NOTHING,
        })
    }

    /// The unit checked.
    pub fn unit_id(&self) -> &str {
        &self.unit_id
    }

    /// Corrects one activation as the firmware would and keeps its figures. Activations are added
    /// in the order the unit lived them: firmware keeps what it knew of each one for the next
    /// switch-on (`power_on_after`; only tables keyed by history read it), and knows from the
    /// recording's off-time when the unit cooled fully ([`cooled_before`]).
    pub fn add(&mut self, segment: &Segment) {
        let window = self.settings.lowpass_window(segment.sample_rate_hz);
        let (uncorrected_drift_dps, _) = metric(&segment.rate_dps, window);
        let switch_on = switch_on_raw(segment, &self.settings);
        if cooled_before(segment, &self.settings) {
            self.previous = Previous::COOLED;
        }
        let (corrected, flags, outside_envelope_samples) = correct_segment_counting(
            &self.model,
            segment,
            switch_on,
            Some(&self.previous),
            Envelope::FLAGS,
        );
        let core = self.model.settings();
        self.previous = kept_after(&self.previous, segment, &self.settings, core);
        let (corrected_drift_dps, residual_rms_dps) = metric(&corrected, window);
        self.activations.push(CheckedActivation {
            labels: segment.labels.clone(),
            uncorrected_drift_dps,
            corrected_drift_dps,
            residual_rms_dps,
            flags,
            samples: segment.len(),
            outside_envelope_samples,
        });
    }

    /// Starts the next activation with nothing kept (a new recording: what happened to the unit
    /// between recordings is not known).
    pub fn forget_history(&mut self) {
        self.previous = Previous::NOTHING;
    }

    /// The activations checked so far.
    pub fn activations(&self) -> &[CheckedActivation] {
        &self.activations
    }

    /// The activations checked, given up with the check.
    pub fn into_activations(self) -> Vec<CheckedActivation> {
        self.activations
    }

    /// The verdict per axis against `limits` (an axis without activations fails: nothing was
    /// checked).
    pub fn verdicts(&self, limits: &Limits) -> [AxisVerdict; 3] {
        [0, 1, 2].map(|axis| verdict(&self.activations, axis, limits))
    }
}

fn verdict(activations: &[CheckedActivation], axis: usize, limits: &Limits) -> AxisVerdict {
    let n = activations.len();
    let mean = |value: &dyn Fn(&CheckedActivation) -> f64| {
        activations.iter().map(value).sum::<f64>() / n.max(1) as f64
    };
    let uncorrected = mean(&|a| a.uncorrected_drift_dps[axis]);
    let corrected = mean(&|a| a.corrected_drift_dps[axis]);
    let rms = mean(&|a| a.residual_rms_dps[axis].powi(2)).sqrt();
    let worst = activations
        .iter()
        .map(|a| a.corrected_drift_dps[axis])
        .fold(0.0, f64::max);
    let removed = if uncorrected > 0.0 {
        1.0 - corrected / uncorrected
    } else {
        0.0
    };
    let count = |flags: Flags| {
        activations
            .iter()
            .filter(|a| Flags(a.flags[axis]).intersects(flags))
            .count()
    };
    let mut failures = Vec::new();
    if n == 0 {
        failures.push("no activations to check".to_owned());
    } else {
        if corrected.is_nan() || corrected > limits.max_drift_dps {
            failures.push(format!(
                "drift left {corrected:.4} °/s > {:.4} °/s",
                limits.max_drift_dps
            ));
        }
        if rms.is_nan() || rms > limits.max_residual_rms_dps {
            failures.push(format!(
                "residual bias RMS {rms:.4} °/s > {:.4} °/s",
                limits.max_residual_rms_dps
            ));
        }
        if removed.is_nan() || removed < limits.min_removed {
            failures.push(format!(
                "removes {:.0} % of the drift < {:.0} %",
                100.0 * removed,
                100.0 * limits.min_removed
            ));
        }
    }
    AxisVerdict {
        axis,
        activations: n,
        uncorrected_drift_dps: uncorrected,
        corrected_drift_dps: corrected,
        worst_drift_dps: worst,
        residual_rms_dps: rms,
        removed,
        ambient_out_of_range: count(Flags::AMBIENT_OUT_OF_RANGE),
        rise_out_of_span: count(Flags::RISE_OUT_OF_SPAN),
        past_last_reference: count(Flags::PAST_LAST_REFERENCE),
        history_unknown_or_out_of_span: count(Flags::HISTORY_UNKNOWN | Flags::HISTORY_OUT_OF_SPAN),
        outside_envelope: count(Envelope::FLAGS),
        samples: activations.iter().map(|a| a.samples).sum(),
        outside_envelope_samples: activations
            .iter()
            .map(|a| a.outside_envelope_samples[axis])
            .sum(),
        faulty: count(FAULT_FLAGS),
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn activation(uncorrected: f64, corrected: f64, rms: f64, flags: u16) -> CheckedActivation {
        CheckedActivation {
            labels: SegmentLabels {
                unit_id: "GIU-01".to_owned(),
                set_point_celsius: 30.0,
                session_set_point_celsius: None,
                series_kind: drift_recording::SeriesKind::Protocol,
                series: 1,
                repeat: 1,
                activation: 1,
                interval_min: Some(1.0),
                off_before_s: Some(60.0),
            },
            uncorrected_drift_dps: [uncorrected; 3],
            corrected_drift_dps: [corrected; 3],
            residual_rms_dps: [rms; 3],
            flags: [flags; 3],
            samples: 100,
            outside_envelope_samples: [if Flags(flags).intersects(Envelope::FLAGS) {
                100
            } else {
                0
            }; 3],
        }
    }

    #[test]
    fn each_limit_fails_on_its_own_and_says_why() {
        let limits = Limits::default();
        let good = [
            activation(0.03, 0.002, 0.003, 0),
            activation(0.02, 0.004, 0.005, 0),
        ];
        let v = verdict(&good, 1, &limits);
        assert!(v.passed(), "{v:?}");
        assert_eq!((v.activations, v.axis), (2, 1));
        assert!((v.corrected_drift_dps - 0.003).abs() < 1e-12);
        assert!((v.worst_drift_dps - 0.004).abs() < 1e-12);
        assert!((v.residual_rms_dps - (0.5f64 * (9e-6 + 25e-6)).sqrt()).abs() < 1e-12);
        assert!((v.removed - 0.88).abs() < 1e-12);

        let drift = verdict(&[activation(0.03, 0.006, 0.003, 0)], 0, &limits);
        assert_eq!(drift.failures, ["drift left 0.0060 °/s > 0.0050 °/s"]);
        let offset = verdict(&[activation(0.03, 0.002, 0.03, 0)], 0, &limits);
        assert_eq!(
            offset.failures,
            ["residual bias RMS 0.0300 °/s > 0.0200 °/s"]
        );
        let little = verdict(&[activation(0.004, 0.003, 0.003, 0)], 0, &limits);
        assert_eq!(little.failures, ["removes 25 % of the drift < 50 %"]);
        let nan = verdict(&[activation(0.03, f64::NAN, 0.003, 0)], 0, &limits);
        assert_eq!(nan.failures.len(), 2, "a NaN never passes: {nan:?}");
        assert!(!verdict(&[], 0, &limits).passed());
    }

    #[test]
    fn limits_that_mean_nothing_are_named() {
        assert_eq!(Limits::default().invalid(), None);
        let negative = Limits {
            max_residual_rms_dps: -1.0,
            ..Limits::default()
        };
        assert_eq!(negative.invalid(), Some(("max_residual_rms_dps", -1.0)));
        let nan = Limits {
            min_removed: f64::NAN,
            ..Limits::default()
        };
        assert_eq!(nan.invalid().map(|(name, _)| name), Some("min_removed"));
        let above_one = Limits {
            min_removed: 2.0,
            ..Limits::default()
        };
        assert_eq!(above_one.invalid(), Some(("min_removed", 2.0)));
    }

    #[test]
    fn envelope_and_faults_are_counted_per_axis() {
        let limits = Limits::default();
        let acts = [
            activation(0.03, 0.002, 0.003, Flags::AMBIENT_OUT_OF_RANGE.0),
            activation(0.03, 0.002, 0.003, Flags::TEMPERATURE_STUCK.0),
            activation(0.03, 0.002, 0.003, 0),
            activation(0.03, 0.002, 0.003, Flags::HISTORY_OUT_OF_SPAN.0),
        ];
        let v = verdict(&acts, 2, &limits);
        assert_eq!(
            (v.ambient_out_of_range, v.rise_out_of_span, v.faulty),
            (1, 0, 1)
        );
        assert_eq!(
            (v.outside_envelope, v.samples, v.outside_envelope_samples),
            (1, 400, 100),
            "the turn-on envelope: switch-on temperature and residual heat"
        );
        assert!(v.passed(), "flags are reported, not failed: {v:?}");
    }
}
