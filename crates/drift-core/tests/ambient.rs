//! A switch-on with the ambient the instrument measured: where the tables read it, that an ambient
//! equal to the switch-on temperature changes nothing, and that no input panics.
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
use drift_core::{
    AxisModel, CorrectorState, Error, Flags, Location, Model, Output, Previous, Problem, Sample,
};
use proptest::prelude::*;

fn raw(model: &impl Model, celsius: f32) -> f32 {
    let s = model.settings();
    celsius * s.raw_per_celsius + s.raw_at_zero_celsius
}

/// A 2-min activation heating by 3 °C from `start` °C, 2 s apart.
fn activation(model: &impl Model, start: f32) -> Vec<Sample> {
    (0..=60)
        .map(|s| {
            let fraction = 1.0 - (-(s as f32) / 20.0).exp();
            Sample {
                since_power_on_ms: s * 2000,
                rate_dps: [0.1, -0.05, 0.03],
                temperature_raw: [raw(model, start + 3.0 * fraction).round(); 3],
            }
        })
        .collect()
}

/// How a switch-on is made.
#[derive(Clone, Copy, Debug)]
enum Start {
    PowerOn,
    Cooled,
    AtAmbient(f32),
    AfterAtAmbient(f32, Previous),
}

fn run<M>(model: &M, start: Start, switch_on: [f32; 3], samples: &[Sample]) -> Vec<Output>
where
    M: Model,
    M::Axis: AxisModel,
    <M::Axis as AxisModel>::State: Copy + Default,
{
    let mut state = CorrectorState::<<M::Axis as AxisModel>::State>::default();
    let started = match start {
        Start::PowerOn => state.power_on(model, switch_on),
        Start::Cooled => {
            let mut cooled = Previous::COOLED;
            state.power_on_after(model, switch_on, &mut cooled)
        }
        Start::AtAmbient(ambient) => state.power_on_at_ambient(model, switch_on, ambient),
        Start::AfterAtAmbient(ambient, kept) => {
            state.power_on_after_at_ambient(model, switch_on, ambient, &mut [kept; 3])
        }
    };
    started.unwrap();
    samples.iter().map(|s| state.correct(model, s)).collect()
}

/// The outputs' bits, flags left out when `flags` is false.
fn bits(outputs: &[Output], flags: bool) -> Vec<[u32; 9]> {
    outputs
        .iter()
        .map(|out| {
            let mut bits = [0; 9];
            for a in 0..3 {
                bits[a] = out.corrected_dps[a].to_bits();
                bits[3 + a] = out.bias_dps[a].to_bits();
                bits[6 + a] = if flags { u32::from(out.flags[a].0) } else { 0 };
            }
            bits
        })
        .collect()
}

/// The paper's tables read at a measured ambient are the tables read at a switch-on temperature
/// there: the initial bias and stage 2 move with the ambient, the rise stays the activation's.
#[test]
fn the_paper_reads_stage_2_and_the_initial_bias_at_the_measured_ambient() {
    let tables = fixture::modified();
    // 2 °C of residual heat over a 28 °C air.
    let warm = activation(&tables, 30.0);
    let at_air = run(
        &tables,
        Start::AtAmbient(28.0),
        [raw(&tables, 30.0); 3],
        &warm,
    );
    let paper = run(&tables, Start::PowerOn, [raw(&tables, 30.0); 3], &warm);
    // The same heating from a switch-on at 28 °C: the same time and rise, stage 2 at 28 °C.
    let cold = activation(&tables, 28.0);
    let at_28 = run(&tables, Start::PowerOn, [raw(&tables, 28.0); 3], &cold);
    for ((a, p), c) in at_air.iter().zip(&paper).zip(&at_28) {
        for axis in 0..3 {
            assert!(
                (a.bias_dps[axis] - c.bias_dps[axis]).abs() < 1e-6,
                "{a:?} {c:?}"
            );
        }
        assert_ne!(a.bias_dps, p.bias_dps);
    }
}

#[test]
fn an_ambient_outside_the_tables_is_flagged_and_one_not_finite_refused() {
    let tables = fixture::modified();
    let mut state = CorrectorState::default();
    let flags = state
        .power_on_at_ambient(&tables, [raw(&tables, 30.0); 3], 55.0)
        .unwrap();
    assert!(flags
        .iter()
        .all(|f| f.contains(Flags::AMBIENT_OUT_OF_RANGE)));
    let before = state;
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let error = state
            .power_on_at_ambient(&tables, [raw(&tables, 30.0); 3], bad)
            .unwrap_err();
        assert_eq!(
            error,
            Error {
                field: "ambient_celsius",
                at: Location::default(),
                problem: Problem::NonFinite
            }
        );
        assert_eq!(
            error.to_string(),
            "ambient_celsius: value is NaN or infinite"
        );
        let mut kept = [Previous {
            ambient_celsius: 29.0,
            switch_off_celsius: 33.0,
        }; 3];
        let original = kept;
        assert!(state
            .power_on_after_at_ambient(&tables, [raw(&tables, 30.0); 3], bad, &mut kept)
            .is_err());
        // Debug text: NaN fields compare unequal to themselves.
        assert_eq!(
            format!("{:?}", (state, kept)),
            format!("{:?}", (before, original)),
            "nothing changed"
        );
    }
}

/// A table keyed by history reads the measured residual heat, known, and `previous` keeps the
/// measured ambient.
#[test]
fn a_history_table_reads_the_measured_residual_heat() {
    let tables = fixture::by_history();
    let samples = activation(&tables, 31.0);
    let mut state = CorrectorState::default();
    let mut kept = Previous::NOTHING;
    let flags = state
        .power_on_after_at_ambient(&tables, [raw(&tables, 31.0); 3], 29.5, &mut kept)
        .unwrap();
    assert!(flags.iter().all(|f| !f.contains(Flags::HISTORY_UNKNOWN)));
    assert!(kept.iter().all(|p| p.ambient_celsius == 29.5));
    let measured: Vec<Output> = samples.iter().map(|s| state.correct(&tables, s)).collect();
    // What the estimate reads from a kept 29.5 °C ambient and a warmer switch-off: the same start.
    let previous = Previous {
        ambient_celsius: 29.5,
        switch_off_celsius: 34.0,
    };
    let estimated = run(
        &tables,
        Start::AfterAtAmbient(29.5, previous),
        [raw(&tables, 31.0); 3],
        &samples,
    );
    let mut state = CorrectorState::default();
    state
        .power_on_after(&tables, [raw(&tables, 31.0); 3], &mut [previous; 3])
        .unwrap();
    let from_history: Vec<Output> = samples.iter().map(|s| state.correct(&tables, s)).collect();
    // X and Y start from the warm starts' bias at the ambient and residual heat either way; Z,
    // with the paper's cold-start bias, reads it at the measured ambient, not at the switch-on.
    let axes = |outputs: &[Output], axis: usize| -> Vec<[u32; 3]> {
        bits(outputs, true)
            .iter()
            .map(|b| [b[axis], b[3 + axis], b[6 + axis]])
            .collect()
    };
    for axis in 0..2 {
        assert_eq!(axes(&estimated, axis), axes(&from_history, axis));
    }
    assert_ne!(axes(&estimated, 2), axes(&from_history, 2));
    // Without a kept switch-off the cooling's progress is unknown, which only the extension reads.
    assert_eq!(bits(&measured, true), bits(&estimated, true));
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        -60.0f32..120.0,
        any::<f32>(),
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// An ambient equal to the switch-on temperature is the paper's start: every output bit
    /// equals `power_on`'s (the flags `power_on_after` after a cooled mark's: the start is known),
    /// on every model.
    #[test]
    fn an_ambient_at_the_switch_on_changes_nothing(on in 15.0f32..45.0) {
        let (m, h, w, r) = (
            fixture::modified(),
            fixture::by_history(),
            fixture::warm_started(),
            fixture::recommended(),
        );
        let (s, t) = (fixture::standard(), fixture::third_order());
        fn same<M>(model: &M, on: f32) -> Result<(), TestCaseError>
        where
            M: Model,
            M::Axis: AxisModel,
            <M::Axis as AxisModel>::State: Copy + Default,
        {
            let raw_on = raw(model, on).round();
            let celsius = model.settings().celsius(raw_on);
            let samples = activation(model, celsius);
            let ambient = run(model, Start::AtAmbient(celsius), [raw_on; 3], &samples);
            let paper = run(model, Start::PowerOn, [raw_on; 3], &samples);
            prop_assert_eq!(bits(&ambient, false), bits(&paper, false));
            let cooled = run(model, Start::Cooled, [raw_on; 3], &samples);
            prop_assert_eq!(bits(&ambient, true), bits(&cooled, true));
            Ok(())
        }
        same(&m, on)?;
        same(&h, on)?;
        same(&w, on)?;
        same(&r, on)?;
        same(&s, on)?;
        same(&t, on)?;
    }

    /// Any switch-on reading, ambient and kept history: an answer or an error naming the input,
    /// never a panic, and a refused start leaves the state as it was.
    #[test]
    fn never_panics(
        on in any_f32(),
        ambient in any_f32(),
        kept_ambient in any_f32(),
        kept_off in any_f32(),
        temperature in any_f32(),
    ) {
        let tables = fixture::by_history();
        let mut state = CorrectorState::default();
        let mut kept = [Previous { ambient_celsius: kept_ambient, switch_off_celsius: kept_off }; 3];
        let before = (state, kept);
        match state.power_on_after_at_ambient(&tables, [on; 3], ambient, &mut kept) {
            Ok(_) => {
                let out = state.correct(&tables, &Sample {
                    since_power_on_ms: 1000,
                    rate_dps: [0.0; 3],
                    temperature_raw: [temperature; 3],
                });
                prop_assert!(out.corrected_dps.iter().all(|c| c.is_finite()));
            }
            Err(error) => {
                prop_assert!(!on.is_finite() || !ambient.is_finite(), "{error}");
                // Debug text: NaN fields compare unequal to themselves.
                prop_assert_eq!(format!("{:?}", (state, kept)), format!("{before:?}"));
            }
        }
        let recommended = fixture::recommended();
        let mut state = CorrectorState::default();
        let _ = state.power_on_at_ambient(&recommended, [on; 3], ambient);
        let extended = fixture::extended();
        let mut state = CorrectorState::default();
        if state.power_on_at_ambient(&extended, [on; 3], ambient).is_ok() {
            let out = state.correct(&extended, &Sample {
                since_power_on_ms: 1000,
                rate_dps: [0.0; 3],
                temperature_raw: [temperature; 3],
            });
            prop_assert!(out.corrected_dps.iter().all(|c| c.is_finite()));
        }
    }
}
