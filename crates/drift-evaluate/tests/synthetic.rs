//! The fitter on synthetic activations from a known analytic model (no simulator, no noise): it must
//! recover tables that remove nearly all of the drift on a set point it did not see.

use std::collections::BTreeMap;

use drift_evaluate::evaluate::{evaluate, ModelKind};
use drift_fit::analyse::analyse;
use drift_fit::{fit_unit, FitSettings};
use drift_recording::{Segment, SegmentLabels, SeriesKind};

const RATE_HZ: u32 = 1000;
/// The models the drift sums are kept for, in this order (found by kind: the evaluation's order
/// grows with every model).
const KINDS: [ModelKind; 5] = [
    ModelKind::Uncorrected,
    ModelKind::Standard,
    ModelKind::ThirdOrder,
    ModelKind::Relative,
    ModelKind::Modified,
];
const SECONDS: u32 = 120;

/// Heating of activation `activation` of a series with `interval_min` minutes off: later
/// activations of short-interval series start warm and rise less.
fn final_rise(interval_min: f64, activation: u32) -> f64 {
    let residual = (-interval_min / 6.0).exp();
    5.0 * (1.0 - 0.5 * residual * (1.0 - 0.6_f64.powi(activation as i32 - 1)))
}

fn segment(set_point: f64, interval_min: f64, activation: u32) -> Segment {
    let n = (RATE_HZ * SECONDS) as usize;
    let rise_end = final_rise(interval_min, activation);
    let dynamics = rise_end / 5.0; // 1 for a fresh start, less for a warm one
    let on_celsius = set_point + 3.0 * (1.0 - dynamics);
    let mut rate: [Vec<f32>; 3] = Default::default();
    let mut raw: [Vec<i16>; 3] = Default::default();
    for i in 0..n {
        let t = i as f64 / f64::from(RATE_HZ);
        let rise = rise_end * (1.0 - (-t / 40.0).exp()) / (1.0 - (-3.0_f64).exp());
        for axis in 0..3 {
            let sign = [1.0, -1.0, 0.5][axis];
            let k = sign
                * 0.004
                * (1.0 + 0.5 * (-t / 15.0).exp())
                * (0.7 + 0.3 * dynamics)
                * (1.0 + 0.02 * (set_point - 30.0));
            let bias0 = 0.1 * sign + 0.002 * (on_celsius - 30.0);
            rate[axis].push((bias0 + k * rise) as f32);
            raw[axis].push(((on_celsius + rise) * 200.0).round() as i16);
        }
    }
    Segment {
        labels: SegmentLabels {
            unit_id: "synthetic".into(),
            set_point_celsius: set_point,
            session_set_point_celsius: None,
            series_kind: SeriesKind::Protocol,
            series: 1,
            repeat: 1,
            activation,
            interval_min: Some(interval_min),
            off_before_s: None,
        },
        sample_rate_hz: RATE_HZ,
        power_on_ns: 0,
        since_power_on: (0..n as u32).collect(),
        rate_dps: rate,
        temperature_raw: raw,
        temperature_scale: drift_recording::TemperatureScale::default(),
        aux: BTreeMap::new(),
    }
}

#[test]
fn noise_free_fit_removes_nearly_all_drift_at_an_unseen_set_point() {
    let settings = FitSettings::default();
    let intervals = [1.0, 2.0, 5.0, 10.0, 15.0, 30.0];
    let mut calibration = Vec::new();
    for set_point in [30.0, 40.0] {
        for &interval in &intervals {
            for activation in 1..=5 {
                calibration
                    .push(analyse(&segment(set_point, interval, activation), &settings).unwrap());
            }
        }
    }
    let fitted = fit_unit(&calibration, &settings).unwrap();
    // 4 short intervals × activations 2–5, plus the merged independent curve.
    assert_eq!(fitted.curve_keys.len(), 17);
    assert_eq!(
        fitted.modified.axes[0].reference_ms.len(),
        settings.reference_count
    );
    assert_eq!(fitted.modified.axes[0].reference_ms[0], 2000);

    let mut before = 0.0;
    let mut after = [0.0; 5];
    for (interval, activation) in [(1.0, 5), (2.0, 3), (5.0, 2), (30.0, 1), (1.0, 2)] {
        let result = evaluate(&fitted, &segment(33.0, interval, activation), &settings);
        for (slot, kind) in after.iter_mut().zip(KINDS) {
            let model = result.models.iter().find(|m| m.model == kind).unwrap();
            *slot += model.drift_dps.iter().sum::<f64>();
        }
        before += result.models[0].drift_dps.iter().sum::<f64>();
        assert_eq!(result.models[0].model, ModelKind::Uncorrected);
    }
    let modified = after[4];
    eprintln!("drift sum over 5 activations × 3 axes: uncorrected {before:.5}, standard {:.5}, 3rd-order {:.5}, relative {:.5}, modified {modified:.5} °/s", after[1], after[2], after[3]);
    assert!(before > 0.05, "synthetic drift too small to test: {before}");
    assert!(
        modified < 0.1 * before,
        "modified left {modified:.5} of {before:.5} °/s"
    );
    // The modified model beats every baseline on data with heating dynamics.
    assert!(
        modified < after[1] && modified < after[2] && modified < after[3],
        "modified {modified} standard {} 3rd {} relative {}",
        after[1],
        after[2],
        after[3]
    );
}

#[test]
fn no_temperature_rise_is_a_clear_error() {
    let settings = FitSettings::default();
    let mut calibration = Vec::new();
    for set_point in [30.0, 40.0] {
        let mut s = segment(set_point, 30.0, 1);
        // A stuck sensor on Y: the same reading throughout.
        let stuck = s.temperature_raw[1][0];
        s.temperature_raw[1].iter_mut().for_each(|r| *r = stuck);
        calibration.push(analyse(&s, &settings).unwrap());
    }
    let error = fit_unit(&calibration, &settings).unwrap_err().to_string();
    assert!(
        error.contains("axis Y") && error.contains("never rises"),
        "{error}"
    );
}

#[test]
fn mismatched_axis_lengths_and_short_activations_are_named() {
    let settings = FitSettings::default();
    let mut s = segment(30.0, 1.0, 2);
    s.rate_dps[2].truncate(1000);
    let error = analyse(&s, &settings).unwrap_err().to_string();
    assert!(
        error.contains("series 1 activation 2") && error.contains("differ in length"),
        "{error}"
    );

    let mut s = segment(30.0, 1.0, 3);
    for axis in 0..3 {
        s.rate_dps[axis].truncate(1500);
        s.temperature_raw[axis].truncate(1500);
    }
    s.since_power_on.truncate(1500);
    let error = analyse(&s, &settings).unwrap_err().to_string();
    assert!(error.contains("1500 samples is too short"), "{error}");
}

/// Calibration data in which one activation's X sensor is stuck (its switch-on reading throughout)
/// or saturated (the int16 limit throughout).
fn calibration_with(
    bad: &dyn Fn(&mut Segment),
) -> Result<drift_fit::FittedUnit, drift_fit::FitError> {
    let settings = FitSettings::default();
    let mut calibration = Vec::new();
    for set_point in [30.0, 40.0] {
        for interval in [1.0, 5.0, 30.0] {
            for activation in 1..=5 {
                let mut s = segment(set_point, interval, activation);
                if set_point == 30.0 && interval == 5.0 && activation == 2 {
                    bad(&mut s);
                }
                calibration.push(analyse(&s, &settings)?);
            }
        }
    }
    fit_unit(&calibration, &settings)
}

#[test]
fn a_stuck_or_saturated_sensor_is_a_documented_degradation() {
    let settings = FitSettings::default();
    let score = |f: &drift_fit::FittedUnit| {
        [(1.0, 5), (5.0, 2), (30.0, 1)]
            .iter()
            .map(|&(i, a)| {
                evaluate(f, &segment(33.0, i, a), &settings)
                    .models
                    .iter()
                    .find(|m| m.model == ModelKind::Modified)
                    .unwrap()
                    .drift_dps[0]
            })
            .sum::<f64>()
    };
    let clean = score(&calibration_with(&|_| {}).unwrap());
    // In calibration: one activation of 30 is outvoted (curves average over activations and set
    // points); the tables leave no more drift on unseen data. (All activations stuck on an axis:
    // "never rises", above.)
    let stuck = score(
        &calibration_with(&|s| {
            let v = s.temperature_raw[0][0];
            s.temperature_raw[0].iter_mut().for_each(|r| *r = v);
        })
        .unwrap(),
    );
    let saturated = score(
        &calibration_with(&|s| s.temperature_raw[0].iter_mut().for_each(|r| *r = i16::MAX))
            .unwrap(),
    );
    assert!(
        stuck < 1.5 * clean && saturated < 1.5 * clean,
        "clean {clean} stuck {stuck} saturated {saturated}"
    );

    // At correction time: a saturated sensor reads +163.8 °C at switch-on, far outside the
    // calibrated ambients (flagged for the whole activation), and its unchanging reading is flagged
    // stuck after `stuck_after_samples`; the correction holds. The other axes are unaffected.
    let fitted = calibration_with(&|_| {}).unwrap();
    let mut s = segment(33.0, 30.0, 1);
    s.temperature_raw[0].iter_mut().for_each(|r| *r = i16::MAX);
    let result = evaluate(&fitted, &s, &settings);
    let modified = result
        .models
        .iter()
        .find(|m| m.model == ModelKind::Modified)
        .unwrap();
    let flags = drift_core::Flags(modified.flags[0]);
    assert!(
        flags.contains(
            drift_core::Flags::AMBIENT_OUT_OF_RANGE | drift_core::Flags::TEMPERATURE_STUCK
        ),
        "{flags:?}"
    );
    assert!(!drift_core::Flags(modified.flags[1]).intersects(drift_core::Flags::FAULTS));
}
