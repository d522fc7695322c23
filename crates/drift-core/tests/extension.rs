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
    Corrector, Extension, ExtensionState, ExtraTerm, Flags, Sample, Term, TermInputs, AXES,
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
    }
}

#[test]
fn temperature_rate_term_follows_a_ramp() {
    // 0.02 °C/s on X, −0.01 on Y, 0 on Z, sampled every ms: after 10 τ the filtered derivative has
    // settled on the slope (its steady-state lag is τ, which a ramp's derivative does not see).
    let extension = rate_only(2000);
    let mut state = ExtensionState::power_on([30.0, 30.0, 30.0]);
    let mut last = [[0.0; 4]; 3];
    for ms in 1..=20_000 {
        let t = ms as f32 / 1000.0;
        let inputs = TermInputs {
            since_power_on_ms: ms,
            celsius: [30.0 + 0.02 * t, 30.0 - 0.01 * t, 30.0],
            ..TermInputs::default()
        };
        last = state.values(&extension, &inputs);
    }
    assert!((last[0][0] - 0.02).abs() < 2e-4, "{last:?}");
    assert!((last[1][0] + 0.01).abs() < 2e-4, "{last:?}");
    assert!(last[2][0].abs() < 1e-6, "{last:?}");
}

#[test]
fn each_term_reads_what_it_names() {
    let terms = [
        Term::Aux { input: 2 },
        Term::AxisRise { axis: 1 },
        Term::RiseSquared,
    ]
    .map(|term| ExtraTerm {
        term,
        centre: [1.0, 2.0, 3.0],
        coefficient: [1.0; AXES],
    });
    let extension = Extension {
        terms: heapless::Vec::from_slice(&terms).unwrap(),
    };
    let mut state = ExtensionState::power_on([25.0; AXES]);
    let values = state.values(
        &extension,
        &TermInputs {
            since_power_on_ms: 10,
            celsius: [26.0, 27.0, 28.0],
            rise_celsius: [1.0, 2.0, 3.0],
            aux: [0.0, 0.0, 7.0, 0.0],
        },
    );
    // values[axis][term] = raw − centre[axis]
    assert_eq!(values[0][..3], [6.0, 1.0, 0.0]);
    assert_eq!(values[1][..3], [5.0, 0.0, 2.0]);
    assert_eq!(values[2][..3], [4.0, -1.0, 6.0]);
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

    /// Any auxiliary bits: no panic; the supply term's input unusable (or absurdly large) ⇔
    /// flagged; the corrected rate stays finite (the last good contribution is held).
    #[test]
    fn arbitrary_aux_is_held_and_flagged(
        aux_bits in prop::collection::vec(prop::array::uniform4(any::<u32>()), 1..60),
    ) {
        let model = fixture::extended();
        let mut corrector = Corrector::new(&model).unwrap();
        corrector.power_on([6600.0, 6640.0, 6580.0]).unwrap();
        for (i, bits) in aux_bits.iter().enumerate() {
            let aux = bits.map(f32::from_bits);
            let raw = [6600.0, 6640.0, 6580.0].map(|r: f32| r + i as f32);
            let out = corrector.correct_with_aux(&sample(1 + 50 * i as u32, raw), &aux);
            // The fixture's only auxiliary term reads input 0, with coefficients of ~0.01 °/s per
            // unit: beyond ~1e6 units its contribution passes MAX_PLAUSIBLE_DRIFT_DPS and is held
            // like a non-finite one.
            let unusable = !aux[0].is_finite() || !(aux[0] - 5.0).is_finite();
            let implausible = aux[0].abs() > 1.0e5;
            for axis in 0..AXES {
                let flagged = out.flags[axis].contains(Flags::EXTENSION_INPUT_INVALID);
                prop_assert!(!unusable || flagged, "unusable input not flagged: {:?}", aux);
                prop_assert!(!flagged || unusable || implausible, "flagged a usable input: {:?}", aux);
                // Held, never passed on: the corrected rate is finite whatever the input.
                prop_assert!(out.corrected_dps[axis].is_finite(), "{:?} -> {:?}", aux, out);
            }
        }
    }
}
