//! Tables keyed by heating history through the corrector: what firmware keeps across power-off,
//! how the next start reads it, and that the paper's tables ignore it.
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
    clippy::cast_precision_loss,
    missing_docs
)]

mod common;

use common::fixture;
use drift_core::{Corrector, Flags, Model, Previous, Sample};

/// Raw units per °C of the fixture's settings.
fn raw(model: &impl Model, celsius: f32) -> f32 {
    let s = model.settings();
    celsius * s.raw_per_celsius + s.raw_at_zero_celsius
}

/// A 2-min activation heating by `rise` °C from `start` °C, 1 s apart.
fn activation(model: &impl Model, start: f32, rise: f32) -> Vec<Sample> {
    (0..=120)
        .map(|s| {
            let fraction = 1.0 - (-(s as f32) / 40.0).exp();
            let celsius = start + rise * fraction;
            Sample {
                since_power_on_ms: s * 1000,
                rate_dps: [0.1, -0.05, 0.03],
                temperature_raw: [raw(model, celsius).round(); 3],
            }
        })
        .collect()
}

fn outputs(corrector: &mut Corrector<'_, impl Model>, samples: &[Sample]) -> Vec<[u32; 9]> {
    samples
        .iter()
        .map(|sample| {
            let out = corrector.correct(sample);
            let mut bits = [0; 9];
            for a in 0..3 {
                bits[a] = out.corrected_dps[a].to_bits();
                bits[3 + a] = out.bias_dps[a].to_bits();
                bits[6 + a] = u32::from(out.flags[a].0);
            }
            bits
        })
        .collect()
}

#[test]
fn a_series_keeps_its_ambient_and_reads_the_residual_heat() {
    let tables = fixture::by_history();
    let mut corrector = Corrector::new(&tables).unwrap();
    let mut previous = Previous::NOTHING;
    // First activation: nothing kept yet, a cold start at 30 °C, flagged.
    let flags = corrector
        .power_on_after([raw(&tables, 30.0); 3], &mut previous)
        .unwrap();
    assert!(flags.iter().all(|f| f.contains(Flags::HISTORY_UNKNOWN)));
    assert!(previous.iter().all(|p| p.ambient_celsius == 30.0));
    assert!(previous.iter().all(|p| p.switch_off_celsius.is_nan()));
    let first = activation(&tables, 30.0, 4.0);
    outputs(&mut corrector, &first);
    corrector.keep(&mut previous);
    let last = first.last().unwrap().temperature_raw[0];
    let switch_off = (last - tables.settings.raw_at_zero_celsius) / tables.settings.raw_per_celsius;
    assert!(previous.iter().all(|p| p.switch_off_celsius == switch_off));
    corrector.power_off();

    // Switched on again still 1.6 °C warm: the ambient stays 30 °C, the residual heat is 1.6 °C.
    let warm = activation(&tables, 31.6, 3.0);
    let flags = corrector
        .power_on_after([raw(&tables, 31.6); 3], &mut previous)
        .unwrap();
    assert!(flags.iter().all(|f| f.is_empty()), "{flags:?}");
    assert!(previous.iter().all(|p| p.ambient_celsius == 30.0));
    let by_history = outputs(&mut corrector, &warm);
    // The same activation without what was kept: a cold start at 31.6 °C, flagged, and another
    // correction.
    let mut unknown = Corrector::new(&tables).unwrap();
    unknown.power_on([raw(&tables, 31.6); 3]).unwrap();
    let cold = outputs(&mut unknown, &warm);
    assert!(cold.iter().all(|o| o[6..]
        .iter()
        .all(|f| f & u32::from(Flags::HISTORY_UNKNOWN.0) != 0)));
    let differ = by_history
        .iter()
        .zip(&cold)
        .filter(|(h, c)| h[3] != c[3])
        .count();
    assert!(
        differ > 100,
        "only {differ} of {} samples differ",
        warm.len()
    );
    // The drift since switch-on is read from the curves at 1.6 °C of residual heat (histories 8
    // and 9 of the fixture at 30 °C are 1.6 and 1.8 °C): history 8's k at the first reference
    // time, whatever the rise.
    let settings = tables.settings;
    let table = &tables.axes[0];
    let t = table.reference_ms[0];
    let index = warm.iter().position(|s| s.since_power_on_ms == t).unwrap();
    let rise = (warm[index].temperature_raw[0] - raw(&tables, 31.6)) / settings.raw_per_celsius;
    let k = table.ambients[1].curves[8].points[0].k_dps_per_celsius;
    let bias = f32::from_bits(by_history[index][3]);
    let initial = corrector.state().axes()[0].initial_bias_dps();
    assert!(
        (bias - initial - k * rise).abs() < 1e-6,
        "{bias} vs {initial} + {k}·{rise}"
    );
}

#[test]
fn keep_records_nothing_before_a_power_on() {
    let tables = fixture::by_history();
    let corrector = Corrector::new(&tables).unwrap();
    let mut previous = [Previous {
        ambient_celsius: 25.0,
        switch_off_celsius: 29.0,
    }; 3];
    corrector.keep(&mut previous);
    assert!(previous.iter().all(|p| p.switch_off_celsius == 29.0));
}

#[test]
fn tables_keyed_by_rise_ignore_what_was_kept() {
    let tables = fixture::modified();
    let samples = activation(&tables, 33.0, 4.0);
    let mut plain = Corrector::new(&tables).unwrap();
    plain.power_on([raw(&tables, 33.0); 3]).unwrap();
    let mut after = Corrector::new(&tables).unwrap();
    let mut previous = [Previous {
        ambient_celsius: 30.0,
        switch_off_celsius: 35.0,
    }; 3];
    after
        .power_on_after([raw(&tables, 33.0); 3], &mut previous)
        .unwrap();
    assert_eq!(outputs(&mut plain, &samples), outputs(&mut after, &samples));
}
