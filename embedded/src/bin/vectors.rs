//! Runs every shared test vector through drift-core on the (emulated) Cortex-M4F and compares each
//! output with the host's bit for bit. Exit status 0 only if all agree. Also reports the run-time
//! state size and the stack used by decoding and by correcting.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use drift_core::blob::{decode, decode_into, decode_section};
use drift_core::{
    AxisModel, Corrector, CorrectorState, Model, ModifiedAxisState, PolynomialTables, Previous,
    Sample,
};
use gyrodrift_embedded::{
    stack, Case, FirmwareRecommended, FirmwareTables, ModelName, BY_HISTORY, CASES, EXTENDED,
    MODIFIED, RECOMMENDED, SIGMA_CASES, SIGMA_SECTION, STANDARD, STILLNESS_CASES, THIRD_ORDER,
    WARM_STARTED,
};
use panic_semihosting as _;

fn fail(what: &str) -> ! {
    hprintln!("FAIL: {}", what);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Stack a firmware may budget for decoding its table image at start-up into a `static`
/// (`decode_into` writes the tables in place: measured in docs/embedded.md). A ceiling, so a change
/// that builds the tables (or a large part of them) on the stack again fails here rather than on
/// a customer's 64-KiB part.
const DECODE_STACK_CEILING: usize = 8 * 1024;

fn same(expected: u32, got: u32) -> bool {
    expected == got || (f32::from_bits(expected).is_nan() && f32::from_bits(got).is_nan())
}

/// Runs one case; returns the number of outputs that differ from the host's.
fn run<M: Model>(model: &M, case: &Case) -> usize
where
    M::Axis: AxisModel,
{
    let Ok(mut corrector) = Corrector::new(model) else {
        fail("model rejected")
    };
    if let Some(raw) = case.switch_on_raw {
        let raw = raw.map(f32::from_bits);
        let started = match case.kept() {
            Some(mut previous) => corrector.power_on_after(raw, &mut previous),
            None => corrector.power_on(raw),
        };
        if started.is_err() != case.power_on_fails {
            hprintln!("power_on outcome differs in {}", case.name);
            return 1;
        }
    }
    let mut mismatches = 0;
    for (i, (input, expected)) in case.samples.iter().zip(case.expected).enumerate() {
        let sample = Sample {
            since_power_on_ms: input[0],
            rate_dps: [input[1], input[2], input[3]].map(f32::from_bits),
            temperature_raw: [input[4], input[5], input[6]].map(f32::from_bits),
        };
        let out = match case.aux.get(i) {
            Some(aux) => corrector.correct_with_aux(&sample, &aux.map(f32::from_bits)),
            None => corrector.correct(&sample),
        };
        let got = [
            out.corrected_dps[0].to_bits(),
            out.corrected_dps[1].to_bits(),
            out.corrected_dps[2].to_bits(),
            out.bias_dps[0].to_bits(),
            out.bias_dps[1].to_bits(),
            out.bias_dps[2].to_bits(),
            u32::from(out.flags[0].0),
            u32::from(out.flags[1].0),
            u32::from(out.flags[2].0),
        ];
        for (k, (&e, &g)) in expected.iter().zip(&got).enumerate() {
            if !same(e, g) {
                mismatches += 1;
                hprintln!(
                    "{} sample {} output {}: expected {:#010x}, got {:#010x}",
                    case.name,
                    i,
                    k,
                    e,
                    g
                );
            }
        }
    }
    mismatches
}

#[entry]
fn main() -> ! {
    // cortex-m-rt turns these into `&'static mut` references, safely: the tables live in RAM
    // outside the stack, and `decode_into` fills them where they are.
    static mut MODIFIED_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut EXTENDED_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut BY_HISTORY_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut WARM_STARTED_TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut RECOMMENDED_TABLES: FirmwareRecommended = FirmwareRecommended::EMPTY;

    let painted = stack::paint();
    if decode_into(black_box(MODIFIED), MODIFIED_TABLES).is_err() {
        fail("modified image did not decode");
    }
    let decode_stack = painted.used();
    let modified: &FirmwareTables = MODIFIED_TABLES;
    let Ok(standard) = decode::<PolynomialTables>(STANDARD) else {
        fail("standard image")
    };
    let Ok(third_order) = decode::<PolynomialTables>(THIRD_ORDER) else {
        fail("third-order image")
    };
    if decode_into(EXTENDED, EXTENDED_TABLES).is_err() {
        fail("extended image");
    }
    let extended: &FirmwareTables = EXTENDED_TABLES;
    let painted = stack::paint();
    if decode_into(black_box(BY_HISTORY), BY_HISTORY_TABLES).is_err() {
        fail("by_history image did not decode");
    }
    let decode_history_stack = painted.used();
    let by_history: &FirmwareTables = BY_HISTORY_TABLES;
    if decode_into(WARM_STARTED, WARM_STARTED_TABLES).is_err() {
        fail("warm_started image");
    }
    let warm_started: &FirmwareTables = WARM_STARTED_TABLES;
    let painted = stack::paint();
    if decode_into(black_box(RECOMMENDED), RECOMMENDED_TABLES).is_err() {
        fail("recommended image did not decode");
    }
    let decode_recommended_stack = painted.used();
    let recommended: &FirmwareRecommended = RECOMMENDED_TABLES;

    let mut samples = 0;
    let mut mismatches = 0;
    for case in CASES {
        samples += case.samples.len();
        mismatches += match case.model {
            ModelName::Modified => run(modified, case),
            ModelName::Standard => run(&standard, case),
            ModelName::ThirdOrder => run(&third_order, case),
            ModelName::Extended => run(extended, case),
            ModelName::ByHistory => run(by_history, case),
            ModelName::WarmStarted => run(warm_started, case),
            ModelName::Recommended => run(recommended, case),
        };
    }

    // σ(t) beside the corrected samples: the section decoded, every case's σ bit for bit.
    let Ok(uncertainty) = decode_section(black_box(SIGMA_SECTION)) else {
        fail("σ(t) section did not decode")
    };
    let mut sigma_outputs = 0;
    for case in SIGMA_CASES {
        case.run(&uncertainty, |i, got| {
            for (k, (&e, &g)) in case.expected[i].iter().zip(&got).enumerate() {
                sigma_outputs += 1;
                if !same(e, g) {
                    mismatches += 1;
                    hprintln!(
                        "σ(t) {} time {} axis {}: expected {:#010x}, got {:#010x}",
                        case.name,
                        i,
                        k,
                        e,
                        g
                    );
                }
            }
        });
    }

    // The stillness learner after the tables: every case's output, states and offset bit for bit.
    let mut stillness_outputs = 0;
    for case in STILLNESS_CASES {
        let offset = case.run(|i, got, states| {
            stillness_outputs += 1;
            let rates_differ = case.expected[i]
                .iter()
                .zip(&got)
                .any(|(&e, &g)| !same(e, g));
            if rates_differ || case.states[i] != states {
                mismatches += 1;
                hprintln!(
                    "stillness {} sample {}: differs from the host",
                    case.name,
                    i
                );
            }
        });
        match offset {
            Some(offset) if offset == case.final_offset => {}
            _ => {
                mismatches += 1;
                hprintln!(
                    "stillness {}: final offset differs from the host",
                    case.name
                );
            }
        }
    }

    // Stack of one power-on plus one corrected sample, measured on a fresh painting.
    let Ok(mut corrector) = Corrector::new(extended) else {
        fail("model rejected")
    };
    let painted = stack::paint();
    let _ = black_box(corrector.power_on(black_box([6600.0, 6640.0, 6580.0])));
    let sample = Sample {
        since_power_on_ms: 33_333,
        rate_dps: [0.1; 3],
        temperature_raw: [6900.0, 6950.0, 6800.0],
    };
    black_box(corrector.correct_with_aux(black_box(&sample), black_box(&[5.0, 0.0, 0.0, 1.0])));
    let correct_stack = painted.used();

    // The same with a table keyed by history: power_on_after, one sample, keep.
    let Ok(mut corrector) = Corrector::new(by_history) else {
        fail("model rejected")
    };
    let mut previous = [Previous {
        ambient_celsius: 30.0,
        switch_off_celsius: 35.0,
    }; 3];
    let painted = stack::paint();
    let _ = black_box(corrector.power_on_after(
        black_box([6600.0, 6640.0, 6580.0]),
        black_box(&mut previous),
    ));
    black_box(corrector.correct(black_box(&sample)));
    corrector.keep(black_box(&mut previous));
    let history_stack = painted.used();

    hprintln!("cases: {}", CASES.len());
    hprintln!("samples: {}", samples);
    hprintln!("outputs compared: {}", samples * 9);
    hprintln!("σ(t) cases: {}", SIGMA_CASES.len());
    hprintln!("σ(t) outputs compared: {}", sigma_outputs);
    hprintln!("stillness cases: {}", STILLNESS_CASES.len());
    hprintln!("stillness samples compared: {}", stillness_outputs);
    hprintln!("mismatches: {}", mismatches);
    hprintln!("σ(t) section bytes: {}", SIGMA_SECTION.len());
    hprintln!("modified image bytes: {}", MODIFIED.len());
    hprintln!(
        "modified tables in RAM, bytes: {}",
        core::mem::size_of::<FirmwareTables>()
    );
    hprintln!(
        "corrector state bytes: {}",
        core::mem::size_of::<CorrectorState<ModifiedAxisState>>()
    );
    hprintln!("by_history image bytes: {}", BY_HISTORY.len());
    hprintln!(
        "previous activation kept across power-off ([Previous; 3]), bytes: {}",
        core::mem::size_of::<[Previous; 3]>()
    );
    hprintln!("recommended image bytes: {}", RECOMMENDED.len());
    hprintln!(
        "recommended tables in RAM, bytes: {}",
        core::mem::size_of::<FirmwareRecommended>()
    );
    hprintln!("stack bytes, decode_into image: {}", decode_stack);
    hprintln!(
        "stack bytes, decode_into by_history image: {}",
        decode_history_stack
    );
    hprintln!(
        "stack bytes, decode_into recommended image: {}",
        decode_recommended_stack
    );
    hprintln!(
        "stack bytes, power_on + correct_with_aux (extended model): {}",
        correct_stack
    );
    hprintln!(
        "stack bytes, power_on_after + correct + keep (by_history model): {}",
        history_stack
    );
    let worst_decode = decode_stack
        .max(decode_history_stack)
        .max(decode_recommended_stack);
    if worst_decode >= stack::DEPTH || worst_decode > DECODE_STACK_CEILING {
        fail("decoding the table image takes more stack than the ceiling (DECODE_STACK_CEILING)");
    }
    if mismatches == 0 {
        hprintln!("PASS: Cortex-M4F outputs are bit-identical to the host's");
        debug::exit(debug::EXIT_SUCCESS);
    } else {
        fail("outputs differ from the host");
    }
    #[allow(clippy::empty_loop)]
    loop {}
}
