//! The extended model's extra terms: what each term measures, that zero coefficients change
//! nothing, and that arbitrary auxiliary inputs never panic and are flagged when unusable.
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
use drift_core::{
    Corrector, Extension, ExtensionState, ExtraTerm, Flags, Previous, Sample, SwitchOn,
    SwitchOnRate, Term, TermInputs, AXES,
};
use proptest::prelude::*;

fn rate_only(time_constant_ms: u32) -> Extension {
    Extension {
        terms: heapless::Vec::from_slice(&[ExtraTerm {
            term: Term::TemperatureRate { time_constant_ms },
            centre: [0.0; AXES],
            coefficient: [1.0; AXES],
        }])
        .unwrap(),
        ..Extension::NONE
    }
}

#[test]
fn temperature_rate_term_follows_a_ramp() {
    // 0.02 °C/s on X, −0.01 on Y, 0 on Z, sampled every ms: after 10 τ the filtered derivative has
    // settled on the slope (its steady-state lag is τ, which a ramp's derivative does not see).
    let extension = rate_only(2000);
    let mut state = ExtensionState::power_on();
    let mut last = [[0.0; 4]; 3];
    for ms in 1..=20_000 {
        let t = ms as f32 / 1000.0;
        let inputs = TermInputs {
            since_power_on_ms: ms,
            rise_celsius: [0.02 * t, -0.01 * t, 0.0],
            ..TermInputs::default()
        };
        last = state.values(&extension, &inputs);
    }
    assert!((last[0][0] - 0.02).abs() < 2e-4, "{last:?}");
    assert!((last[1][0] + 0.01).abs() < 2e-4, "{last:?}");
    assert!(last[2][0].abs() < 1e-6, "{last:?}");
}

#[test]
fn a_rate_filter_started_from_the_cooling_reads_it_until_the_heating_takes_over() {
    // Heating at 0.15 °C/s; cooling at 1/250 s per °C plus 1/100 s per unit of the switch-off
    // heat left.
    let extension = Extension {
        switch_on_rate: [SwitchOnRate {
            heating_celsius_per_s: 0.15,
            cooling_per_second: 0.004,
            cooling_per_second_per_remaining: 0.01,
        }; AXES],
        ..rate_only(30_000)
    };
    let kept = Previous {
        ambient_celsius: 30.0,
        switch_off_celsius: 35.0,
    };
    // X: 2 °C of the 5 °C left; Y: nothing kept (taken as cold: the heating alone); Z: known
    // cooled (cold).
    let starts = [
        SwitchOn::estimate(32.0, Some(kept)),
        SwitchOn::estimate(32.0, None),
        SwitchOn::estimate(32.0, Some(Previous::COOLED[2])),
    ];
    let expected_x = 0.15 - 2.0 * (0.004 + 0.01 * 0.4);
    assert!((extension.switch_on_rate[0].rate(&starts[0]) - expected_x).abs() < 1e-7);
    let mut state = ExtensionState::power_on_after(&extension, &starts);
    let first = state.values(
        &extension,
        &TermInputs {
            since_power_on_ms: 0,
            ..TermInputs::default()
        },
    );
    assert!((first[0][0] - expected_x).abs() < 1e-6, "{first:?}");
    assert!((first[1][0] - 0.15).abs() < 1e-6 && (first[2][0] - 0.15).abs() < 1e-6);
    // Without a rate term the start changes nothing.
    assert_eq!(
        ExtensionState::power_on_after(&Extension::NONE, &starts),
        ExtensionState::POWER_ON
    );
    // A steady heating of 0.03 °C/s from switch-on: the estimate moves from the start towards it
    // with the filter's τ (30 s), and after 10 τ it reads the ramp alone.
    let mut last = first;
    for ms in (100..=300_000).step_by(100) {
        let t = ms as f32 / 1000.0;
        last = state.values(
            &extension,
            &TermInputs {
                since_power_on_ms: ms,
                rise_celsius: [0.03 * t; AXES],
                ..TermInputs::default()
            },
        );
    }
    assert!((last[0][0] - 0.03).abs() < 1e-4, "{last:?}");
}

#[test]
fn each_term_reads_what_it_names() {
    let terms = [
        Term::Aux {
            input: 2,
            time_constant_ms: 0,
        },
        Term::AxisRise { axis: 1 },
        Term::RiseSquared,
        Term::AuxTimesRise {
            input: 2,
            time_constant_ms: 0,
        },
    ]
    .map(|term| ExtraTerm {
        term,
        centre: [1.0, 2.0, 3.0],
        coefficient: [1.0; AXES],
    });
    let extension = Extension {
        terms: heapless::Vec::from_slice(&terms).unwrap(),
        ..Extension::NONE
    };
    let mut state = ExtensionState::power_on();
    let values = state.values(
        &extension,
        &TermInputs {
            since_power_on_ms: 10,
            rise_celsius: [1.0, 2.0, 3.0],
            aux: [0.0, 0.0, 7.0, 0.0],
        },
    );
    // values[axis][term] = raw − centre[axis]; the last term is input 2 × the axis's own rise.
    assert_eq!(values[0], [6.0, 1.0, 0.0, 6.0]);
    assert_eq!(values[1], [5.0, 0.0, 2.0, 12.0]);
    assert_eq!(values[2], [4.0, -1.0, 6.0, 18.0]);
    // Before its input's first finite value the interaction adds nothing (its centre).
    let mut waiting = ExtensionState::power_on();
    let values = waiting.values(
        &extension,
        &TermInputs {
            since_power_on_ms: 10,
            rise_celsius: [1.0, 2.0, 3.0],
            aux: [f32::NAN; 4],
        },
    );
    assert_eq!([values[0][3], values[1][3], values[2][3]], [0.0; AXES]);
    let fewer = Extension {
        terms: heapless::Vec::from_slice(&terms[..3]).unwrap(),
        ..Extension::NONE
    };
    let values = ExtensionState::power_on().values(&fewer, &TermInputs::default());
    assert_eq!(values[0][3], 0.0, "unused term slots are 0");
}

fn sample(ms: u32, raw: [f32; 3]) -> Sample {
    Sample {
        since_power_on_ms: ms,
        rate_dps: [0.1, -0.2, 0.05],
        temperature_raw: raw,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Zero coefficients: bit-identical to the paper's model, whatever the inputs.
    #[test]
    fn zero_coefficients_change_nothing(
        aux in prop::array::uniform4(-10.0f32..10.0),
        rises in prop::collection::vec(prop::array::uniform3(0.0f32..6.0), 1..40),
    ) {
        let base = fixture::modified();
        let mut extension = fixture::extended().extension;
        for term in &mut extension.terms {
            term.coefficient = [0.0; AXES];
        }
        let zeroed = fixture::modified().with_extension(extension).unwrap();
        let mut plain = Corrector::new(&base).unwrap();
        let mut extended = Corrector::new(&zeroed).unwrap();
        plain.power_on([6600.0; 3]).unwrap();
        extended.power_on([6600.0; 3]).unwrap();
        for (i, rise) in rises.iter().enumerate() {
            let s = sample(1 + 997 * i as u32, rise.map(|r| 6600.0 + (200.0 * r).round()));
            prop_assert_eq!(plain.correct(&s), extended.correct_with_aux(&s, &aux));
        }
    }

    /// Any auxiliary bits: no panic; a non-finite supply input is flagged (its term holds its
    /// filter); a moderate one is not; the corrected rate always stays finite (an implausible
    /// sum adds nothing, flagged).
    #[test]
    fn arbitrary_aux_is_held_and_flagged(
        aux_bits in prop::collection::vec(prop::array::uniform4(any::<u32>()), 1..60),
    ) {
        let model = fixture::extended();
        let mut corrector = Corrector::new(&model).unwrap();
        corrector.power_on([6600.0, 6640.0, 6580.0]).unwrap();
        let mut all_moderate = true;
        for (i, bits) in aux_bits.iter().enumerate() {
            let aux = bits.map(f32::from_bits);
            let raw = [6600.0, 6640.0, 6580.0].map(|r: f32| r + i as f32);
            let out = corrector.correct_with_aux(&sample(1 + 50 * i as u32, raw), &aux);
            // The fixture's only auxiliary term reads input 0, with coefficients of ~0.01 °/s per
            // unit: an input beyond ~1e6 (held in the filter for a while) makes its contribution
            // implausible (> MAX_PLAUSIBLE_DRIFT_DPS), which adds nothing, flagged.
            all_moderate &= !aux[0].is_finite() || aux[0].abs() < 1e5;
            for axis in 0..AXES {
                let flagged = out.flags[axis].contains(Flags::EXTENSION_INPUT_INVALID);
                if !aux[0].is_finite() {
                    prop_assert!(flagged);
                } else if all_moderate {
                    prop_assert!(!flagged);
                }
                prop_assert!(out.corrected_dps[axis].is_finite());
            }
        }
    }

    /// Any kept history and any valid switch-on rate: `power_on_after` starts the rate filter
    /// without a panic, the corrected rates stay finite, and a start with nothing finite kept is
    /// the heating alone, as after `power_on`.
    #[test]
    fn any_kept_history_starts_the_rate_filter_finitely(
        kept_bits in prop::array::uniform3(prop::array::uniform2(any::<u32>())),
        switch_on in prop::array::uniform3(5000.0f32..8000.0),
        heating in -1.0f32..1.0,
        cooling in 0.0f32..0.1,
        faster in -0.1f32..0.1,
    ) {
        let mut model = fixture::extended();
        let rate = drift_core::SwitchOnRate {
            heating_celsius_per_s: heating,
            cooling_per_second: cooling,
            cooling_per_second_per_remaining: faster.max(-cooling),
        };
        let mut extension = model.extension.clone();
        extension.switch_on_rate = [rate; AXES];
        model = model.with_extension(extension).unwrap();
        let kept = kept_bits.map(|[ambient, off]| Previous {
            ambient_celsius: f32::from_bits(ambient),
            switch_off_celsius: f32::from_bits(off),
        });
        let mut after = Corrector::new(&model).unwrap();
        after.power_on_after(switch_on, &mut kept.clone()).unwrap();
        let mut plain = Corrector::new(&model).unwrap();
        plain.power_on(switch_on).unwrap();
        for i in 0..20u32 {
            let raw = switch_on.map(|r| r + i as f32);
            let s = sample(1 + 500 * i, raw);
            let aux = [5.0; 4];
            let (a, p) = (after.correct_with_aux(&s, &aux), plain.correct_with_aux(&s, &aux));
            for (axis, kept) in kept.iter().enumerate() {
                prop_assert!(a.corrected_dps[axis].is_finite() && a.bias_dps[axis].is_finite());
                let nothing_kept =
                    !(kept.ambient_celsius.is_finite() && kept.switch_off_celsius.is_finite());
                if nothing_kept {
                    prop_assert_eq!(a.corrected_dps[axis].to_bits(), p.corrected_dps[axis].to_bits());
                }
            }
        }
    }
}

fn aux_only(time_constant_ms: u32) -> Extension {
    Extension {
        terms: heapless::Vec::from_slice(&[ExtraTerm {
            term: Term::Aux {
                input: 1,
                time_constant_ms,
            },
            centre: [5.0; AXES],
            coefficient: [1.0; AXES],
        }])
        .unwrap(),
        ..Extension::NONE
    }
}

fn aux_value(state: &mut ExtensionState, extension: &Extension, ms: u32, input: f32) -> f32 {
    let inputs = TermInputs {
        since_power_on_ms: ms,
        aux: [0.0, input, 0.0, 0.0],
        ..TermInputs::default()
    };
    state.values(extension, &inputs)[0][0]
}

#[test]
fn auxiliary_terms_low_pass_their_input_and_hold_through_gaps() {
    // A 5 V supply with ±2 mV alternating noise at 100 Hz: through τ = 1 s the term's
    // peak-to-peak is ~1 % of the input's; unfiltered (τ = 0) it is the input's, exactly.
    let noisy = |i: u32| 5.0 + if i % 2 == 0 { 0.002 } else { -0.002 };
    for (tau, most) in [(1000, 5e-5), (0, 4.1e-3)] {
        let extension = aux_only(tau);
        let mut state = ExtensionState::power_on();
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for i in 0..1000 {
            let value = aux_value(&mut state, &extension, 10 * i, noisy(i));
            if i >= 500 {
                (lo, hi) = (lo.min(value), hi.max(value));
            }
        }
        assert!(hi - lo < most, "τ = {tau} ms: {lo} .. {hi}");
    }
    // Until τ has passed the filter is the mean of the inputs so far: the first reading's noise
    // does not linger (the 11th alternating reading leaves the filter within 0.2 mV of 5 V).
    let extension = aux_only(1000);
    let mut state = ExtensionState::power_on();
    let mut value = 0.0;
    for i in 0..=10 {
        value = aux_value(&mut state, &extension, 10 * i, noisy(i));
    }
    assert!(value.abs() < 2e-4, "{value}");
    // A step from 5 to 6 V once τ has passed: after one more τ the filter has covered 1 − 1/e of
    // it (backward Euler at 1 ms steps: within 0.1 %).
    let mut state = ExtensionState::power_on();
    assert_eq!(aux_value(&mut state, &extension, 0, 5.0), 0.0);
    for ms in 1..=2000 {
        aux_value(&mut state, &extension, ms, 5.0);
    }
    for ms in 2001..=3000 {
        value = aux_value(&mut state, &extension, ms, 6.0);
    }
    assert!((value - (1.0 - (-1.0f32).exp())).abs() < 1e-3, "{value}");
    // A NaN input holds the filter; before any finite input the term is 0 (its centre).
    assert_eq!(aux_value(&mut state, &extension, 3001, f32::NAN), value);
    let mut fresh = ExtensionState::power_on();
    assert_eq!(aux_value(&mut fresh, &extension, 5, f32::NAN), 0.0);
    assert_eq!(aux_value(&mut fresh, &extension, 6, 5.5), 0.5);
}
