//! Documented behaviour under faults and outside the envelope: hold, flag, pass through, reject.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::cast_possible_truncation,
    missing_docs
)]

mod common;

use common::fixture;
use drift_core::{Corrector, Flags, Location, Model, Problem, Sample, Settings};

fn sample(ms: u32, rise: f32) -> Sample {
    Sample {
        since_power_on_ms: ms,
        rate_dps: [0.2, -0.1, 0.05],
        temperature_raw: [6600.0 + 200.0 * rise; 3],
    }
}

#[test]
fn nan_temperature_holds_the_last_good_correction_and_recovers() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    let good = corrector.correct(&sample(30_000, 2.0));
    assert!(good.flags.iter().all(|f| f.is_empty()), "{:?}", good.flags);
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut s = sample(31_000, 2.5);
        s.temperature_raw[0] = bad;
        let held = corrector.correct(&s);
        assert!(held.flags[0].contains(Flags::TEMPERATURE_INVALID));
        assert_eq!(held.bias_dps[0], good.bias_dps[0], "held bias");
        assert!(held.corrected_dps[0].is_finite());
        // The other axes are corrected normally.
        assert!(held.flags[1].is_empty() && held.bias_dps[1] != good.bias_dps[1]);
    }
    let recovered = corrector.correct(&sample(32_000, 2.6));
    assert!(recovered.flags[0].is_empty());
    assert_ne!(recovered.bias_dps[0], good.bias_dps[0]);
}

#[test]
fn stuck_temperature_is_flagged_after_the_limit_and_clears_on_change() {
    let model = fixture::modified();
    let limit = model.settings().stuck_after_samples as u32;
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    let mut last = None;
    for i in 0..=limit {
        let out = corrector.correct(&sample(10_000 + i, 1.0));
        let stuck = out.flags[0].contains(Flags::TEMPERATURE_STUCK);
        assert_eq!(stuck, i >= limit, "sample {i}");
        if stuck {
            assert_eq!(out.bias_dps[0], last.unwrap(), "held while stuck");
        }
        last = Some(out.bias_dps[0]);
    }
    let out = corrector.correct(&sample(20_000, 1.5));
    assert!(!out.flags[0].contains(Flags::TEMPERATURE_STUCK));
}

#[test]
fn stuck_check_can_be_disabled() {
    let mut model = fixture::modified();
    model.settings = Settings {
        stuck_after_samples: 0,
        ..model.settings
    };
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    for i in 0..100 {
        assert!(corrector.correct(&sample(10_000 + i, 1.0)).flags[0].is_empty());
    }
}

#[test]
fn nan_rate_passes_through_flagged_without_disturbing_the_state() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    let mut s = sample(5_000, 0.5);
    s.rate_dps[2] = f32::NAN;
    let out = corrector.correct(&s);
    assert!(out.corrected_dps[2].is_nan());
    assert!(out.flags[2].contains(Flags::RATE_INVALID));
    assert!(out.bias_dps[2].is_finite());
    let next = corrector.correct(&sample(5_001, 0.5));
    assert!(next.flags[2].is_empty() && next.corrected_dps[2].is_finite());
}

#[test]
fn power_on_rejects_non_finite_temperature_naming_the_axis_and_keeps_state() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    let before = *corrector.state();
    let error = corrector.power_on([6600.0, 6600.0, f32::NAN]).unwrap_err();
    assert_eq!(error.at, Location::axis(2));
    assert_eq!(
        error.to_string(),
        "axes[2].switch_on_raw: value is NaN or infinite"
    );
    assert_eq!(*corrector.state(), before);
}

#[test]
fn samples_before_power_on_and_after_power_off_pass_through_flagged() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    let out = corrector.correct(&sample(0, 0.0));
    assert_eq!(out.corrected_dps, [0.2, -0.1, 0.05]);
    assert!(out.flags.iter().all(|f| *f == Flags::NOT_POWERED_ON));
    corrector.power_on([6600.0; 3]).unwrap();
    assert!(corrector.correct(&sample(1, 0.0)).flags[0].is_empty());
    corrector.power_off();
    assert!(corrector.correct(&sample(2, 0.0)).flags[0].contains(Flags::NOT_POWERED_ON));
}

#[test]
fn envelope_flags_clamp_and_say_so() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    // 10 °C: below the 20–40 °C calibration, flagged for the whole activation.
    let flags = corrector.power_on([2000.0; 3]).unwrap();
    assert!(flags
        .iter()
        .all(|f| f.contains(Flags::AMBIENT_OUT_OF_RANGE)));
    let s = Sample {
        since_power_on_ms: 150_000,
        rate_dps: [0.0; 3],
        temperature_raw: [2000.0 + 200.0 * 30.0; 3],
    };
    let out = corrector.correct(&s);
    for f in out.flags {
        assert!(
            f.contains(
                Flags::AMBIENT_OUT_OF_RANGE | Flags::RISE_OUT_OF_SPAN | Flags::PAST_LAST_REFERENCE
            ),
            "{f:?}"
        );
        assert!(!f.intersects(Flags::FAULTS));
    }
    assert!(out.corrected_dps.iter().all(|c| c.is_finite()));
}

#[test]
fn validation_names_field_and_index() {
    let mut tables = fixture::modified();
    tables.axes[2].reference_ms[5] = tables.axes[2].reference_ms[4];
    let error = tables.validate().unwrap_err();
    assert_eq!(
        error.to_string(),
        "axes[2].reference_ms[5]: not strictly greater than the previous value"
    );

    let mut tables = fixture::modified();
    tables.axes[0].ambients[1].curves[3].points.pop();
    let error = tables.validate().unwrap_err();
    assert_eq!(
        error.problem,
        Problem::LengthMismatch {
            expected: 8,
            found: 7
        }
    );
    assert_eq!(
        error.to_string(),
        "axes[0].ambients[1].curves[3].points: has 7 entries, expected 8"
    );

    let mut tables = fixture::modified();
    let (a, b) = (
        tables.axes[1].ambients[0].curves[6].points[2].rise_celsius,
        tables.axes[1].ambients[0].curves[7].points[2].rise_celsius,
    );
    tables.axes[1].ambients[0].curves[6].points[2].rise_celsius = b;
    tables.axes[1].ambients[0].curves[7].points[2].rise_celsius = a;
    assert_eq!(tables.validate().unwrap_err().to_string(), "axes[1].ambients[0].curves[7].points[2].rise_celsius: not strictly greater than the previous value");

    let mut tables = fixture::modified();
    tables.axes[0].ambients[2].ambient_celsius = 25.0;
    assert_eq!(
        tables.validate().unwrap_err().to_string(),
        "axes[0].ambient_celsius[2]: not strictly greater than the previous value"
    );

    let mut tables = fixture::modified();
    tables.settings.raw_per_celsius = 0.0;
    assert_eq!(
        tables.validate().unwrap_err().to_string(),
        "raw_per_celsius: must be greater than zero"
    );
    assert!(Corrector::new(&tables).is_err());
}

#[test]
fn hours_of_operation_keep_integer_time() {
    let model = fixture::modified();
    let mut corrector = Corrector::new(&model).unwrap();
    corrector.power_on([6600.0; 3]).unwrap();
    let at_end = corrector.correct(&sample(120_000, 3.0));
    let after_hours = corrector.correct(&sample(10 * 3_600_000 + 1, 3.0));
    // Past the last reference time k is held: same rise, same drift, however late.
    assert_eq!(at_end.bias_dps, after_hours.bias_dps);
    assert!(after_hours.flags[0].contains(Flags::PAST_LAST_REFERENCE));
}

/// Finding F3: a temperature reading far outside any sensor (finite, so not `TEMPERATURE_INVALID`)
/// made the bias ~1e33 °/s, and `rate − bias` overflowed for rates near `f32::MAX` with only clamp
/// flags set. Such a drift is now implausible: flagged `MODEL_INVALID` and the last good one held,
/// in the per-sample and the block path alike.
#[test]
fn an_absurd_temperature_reading_is_flagged_and_never_overflows_the_output() {
    let model = fixture::modified();
    let mut per_sample = Corrector::new(&model).unwrap();
    per_sample.power_on([6600.0; 3]).unwrap();
    let good = per_sample.correct(&sample(30_000, 2.0));
    let mut block = per_sample.clone();
    let mut inputs = Vec::new();
    for (i, raw) in [1.0e20_f32, -1.0e20, 3.0e38, -3.0e38]
        .into_iter()
        .enumerate()
    {
        let mut s = sample(31_000 + i as u32, 2.5);
        s.temperature_raw[0] = raw;
        s.rate_dps[0] = if i % 2 == 0 { f32::MAX } else { -f32::MAX };
        inputs.push(s);
    }
    let mut from_block = vec![drift_core::Output::default(); inputs.len()];
    block.correct_block(&inputs, &mut from_block);
    for (s, blocked) in inputs.iter().zip(&from_block) {
        let out = per_sample.correct(s);
        assert!(out.flags[0].contains(Flags::MODEL_INVALID), "{out:?}");
        assert_eq!(out.bias_dps[0], good.bias_dps[0], "held bias");
        assert!(out.corrected_dps[0].is_finite(), "{out:?}");
        assert_eq!(out, *blocked, "block path");
        // The other axes are corrected normally.
        assert!(!out.flags[1].contains(Flags::MODEL_INVALID));
    }
}
