//! Instruction counting: corrects 120 samples of a 2-min activation (between calibration ambients,
//! inside the stored curves: the full three-stage path) with each model, between calls to `marker`.
//! `scripts/count-instructions.sh` runs this under QEMU's single-step execution log and counts the
//! instructions executed between consecutive markers.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use drift_core::blob::{decode, decode_into, decode_section};
use drift_core::{
    AxisModel, Corrector, Model, PolynomialTables, Previous, Sample, StillnessLearner,
    StillnessSettings, SwitchOn, Uncertainty,
};
use gyrodrift_embedded::{
    FirmwareRecommended, FirmwareTables, BY_HISTORY, EXTENDED, MODIFIED, RECOMMENDED,
    SIGMA_SECTION, STANDARD,
};
use panic_semihosting as _;

/// Samples corrected between two markers.
const SAMPLES: usize = 120;

/// The script finds this function's entry address in the execution log. The inline assembly keeps
/// LTO from removing or inlining a call that otherwise has no effect.
#[inline(never)]
#[no_mangle]
pub extern "C" fn gyrodrift_marker(id: u32) {
    black_box(id);
    cortex_m::asm::nop();
}

/// `SAMPLES` samples of a 2-minute activation: one per second (`spacing_ms = 1000`: every
/// reference-time segment and most curve brackets change between samples, the worst case), or
/// 1 ms apart in 10 windows of 12 spread over the activation (`spacing_ms = 1`: what 1000 Hz
/// firmware sees).
fn activation(spacing_ms: u32) -> [Sample; SAMPLES] {
    core::array::from_fn(|i| {
        let ms = if spacing_ms == 1 {
            (i as u32 / 12) * 12_000 + i as u32 % 12 + 1
        } else {
            1000 * i as u32 + 1
        };
        let t = ms as f32 / 1000.0;
        // Rise follows an exponential approach, 4 °C after 2 min, kept inside the fixture's curves.
        let shape = 1.0 - libm_free_exp(-t / 60.0);
        Sample {
            since_power_on_ms: ms,
            rate_dps: [0.1, -0.05, 0.02],
            temperature_raw: [
                6600.0 + 200.0 * 4.0 * shape,
                6640.0 + 200.0 * 3.5 * shape,
                6580.0 + 200.0 * 5.0 * shape,
            ],
        }
    })
}

/// e^x for x ≤ 0 by a short series with range halving; only shapes test inputs.
fn libm_free_exp(x: f32) -> f32 {
    let mut y = x / 16.0;
    y = 1.0 + y * (1.0 + y * (0.5 + y * (1.0 / 6.0 + y / 24.0)));
    for _ in 0..4 {
        y *= y;
    }
    y
}

fn measure<M: Model>(model: &M, samples: &[Sample], id: u32)
where
    M::Axis: AxisModel,
{
    let Ok(mut corrector) = Corrector::new(model) else {
        return;
    };
    let _ = corrector.power_on([6600.0, 6640.0, 6580.0]);
    gyrodrift_marker(id);
    for sample in samples {
        black_box(corrector.correct(black_box(sample)));
    }
    gyrodrift_marker(id + 1);
}

/// As `measure`, started with `power_on_after` from a kept previous activation: a warm start
/// (ambient 31 °C, between the 30 and 40 °C calibration ambients; switch-on 33 °C, so ~2 °C of
/// residual heat, between two stored histories: both blends active).
fn measure_after<M: Model>(model: &M, samples: &[Sample], id: u32)
where
    M::Axis: AxisModel,
{
    let Ok(mut corrector) = Corrector::new(model) else {
        return;
    };
    let mut previous = [Previous {
        ambient_celsius: 31.0,
        switch_off_celsius: 36.0,
    }; 3];
    let _ = corrector.power_on_after([6600.0, 6640.0, 6580.0], &mut previous);
    gyrodrift_marker(id);
    for sample in samples {
        black_box(corrector.correct(black_box(sample)));
    }
    gyrodrift_marker(id + 1);
    corrector.keep(black_box(&mut previous));
}

/// As `measure`, with auxiliary inputs (supply voltage, gravity) for the extended model.
fn measure_with_aux<M: Model>(model: &M, samples: &[Sample], id: u32)
where
    M::Axis: AxisModel,
{
    let Ok(mut corrector) = Corrector::new(model) else {
        return;
    };
    let _ = corrector.power_on([6600.0, 6640.0, 6580.0]);
    let aux = [5.0, 0.0, 0.0, 1.0];
    gyrodrift_marker(id);
    for sample in samples {
        black_box(corrector.correct_with_aux(black_box(sample), black_box(&aux)));
    }
    gyrodrift_marker(id + 1);
}

/// σ(t) per sample after a warm restart (class and distance fixed at switch-on, as `measure_after`
/// starts), alone: what a firmware adds beside each corrected sample to hand its filter σ.
fn measure_sigma(uncertainty: &Uncertainty, samples: &[Sample], id: u32) {
    let switch_on = [SwitchOn::estimate(
        33.0,
        Some(Previous {
            ambient_celsius: 31.0,
            switch_off_celsius: 36.0,
        }),
    ); 3];
    let state = uncertainty.start(black_box(&switch_on));
    gyrodrift_marker(id);
    for sample in samples {
        black_box(uncertainty.sigma_dps(&state, black_box(sample).since_power_on_ms));
    }
    gyrodrift_marker(id + 1);
}

/// The stillness learner per gyro sample on its longest path: every sample still and learning
/// (no wait), with an accelerometer seen (its variance joins the test), alone: what a firmware
/// adds after the corrector.
fn measure_stillness(samples: &[Sample], id: u32) {
    let settings = StillnessSettings {
        sample_rate_hz: 1000.0,
        still_for_s: 0.0,
        ..StillnessSettings::default()
    };
    let Ok(mut learner) = StillnessLearner::new(black_box(&settings)) else {
        hprintln!("FAIL: stillness settings refused");
        debug::exit(debug::EXIT_FAILURE);
        #[allow(clippy::empty_loop)]
        loop {}
    };
    learner.accelerometer(black_box([0.0, 0.0, 1.0]));
    learner.accelerometer(black_box([0.0, 0.0, 1.0]));
    gyrodrift_marker(id);
    for sample in samples {
        black_box(learner.update(black_box(sample).rate_dps));
    }
    gyrodrift_marker(id + 1);
}

#[entry]
fn main() -> ! {
    // The tables live in `static`s (cortex-m-rt makes these `&'static mut`), decoded in place.
    static mut MODIFIED_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut EXTENDED_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut BY_HISTORY_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut RECOMMENDED_TABLES: FirmwareRecommended = FirmwareRecommended::EMPTY;
    let samples = activation(1000);
    let at_1khz = activation(1);
    let decoded = (
        decode_into(black_box(MODIFIED), MODIFIED_TABLES),
        decode::<PolynomialTables>(black_box(STANDARD)),
        decode_into(black_box(EXTENDED), EXTENDED_TABLES),
        decode_into(black_box(BY_HISTORY), BY_HISTORY_TABLES),
        decode_into(black_box(RECOMMENDED), RECOMMENDED_TABLES),
    );
    let (modified, extended, by_history): (&FirmwareTables, &FirmwareTables, &FirmwareTables) =
        (MODIFIED_TABLES, EXTENDED_TABLES, BY_HISTORY_TABLES);
    let recommended: &FirmwareRecommended = RECOMMENDED_TABLES;
    match decoded {
        (Ok(()), Ok(standard), Ok(()), Ok(()), Ok(())) => {
            hprintln!("samples per interval: {}", SAMPLES);
            hprintln!("interval 1: modified model, samples 1 s apart (worst case)");
            measure(modified, &samples, 1);
            hprintln!("interval 3: standard polynomial, samples 1 s apart");
            measure(&standard, &samples, 3);
            hprintln!("interval 5: modified model, 1000 Hz windows");
            measure(modified, &at_1khz, 5);
            hprintln!("interval 7: harness only (loop, sample and output moves)");
            gyrodrift_marker(7);
            for sample in &samples {
                black_box(black_box(sample).rate_dps);
                black_box(drift_core::Output::default());
            }
            gyrodrift_marker(8);
            hprintln!("interval 9: modified model + 4 extra terms (extended), samples 1 s apart");
            measure_with_aux(extended, &samples, 9);
            hprintln!("interval 11: modified model + 4 extra terms (extended), 1000 Hz windows");
            measure_with_aux(extended, &at_1khz, 11);
            hprintln!(
                "interval 13: modified model, stage 3 keyed by history (by_history, power_on_after), samples 1 s apart"
            );
            measure_after(by_history, &samples, 13);
            hprintln!(
                "interval 15: modified model, stage 3 keyed by history (by_history, power_on_after), 1000 Hz windows"
            );
            measure_after(by_history, &at_1khz, 15);
            hprintln!("interval 17: recommended model (power_on_after), samples 1 s apart");
            measure_after(recommended, &samples, 17);
            hprintln!("interval 19: recommended model (power_on_after), 1000 Hz windows");
            measure_after(recommended, &at_1khz, 19);
            let Ok(uncertainty) = decode_section(black_box(SIGMA_SECTION)) else {
                hprintln!("FAIL: σ(t) section did not decode");
                debug::exit(debug::EXIT_FAILURE);
                #[allow(clippy::empty_loop)]
                loop {}
            };
            hprintln!("interval 21: σ(t) beside each sample (sigma), samples 1 s apart");
            measure_sigma(&uncertainty, &samples, 21);
            hprintln!("interval 23: σ(t) beside each sample (sigma), 1000 Hz windows");
            measure_sigma(&uncertainty, &at_1khz, 23);
            hprintln!(
                "interval 25: stillness learner after the tables (stillness), still and learning, 1000 Hz gyro samples"
            );
            measure_stillness(&at_1khz, 25);
            debug::exit(debug::EXIT_SUCCESS);
        }
        _ => {
            hprintln!("FAIL: images did not decode");
            debug::exit(debug::EXIT_FAILURE);
        }
    }
    #[allow(clippy::empty_loop)]
    loop {}
}
