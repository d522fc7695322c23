//! The smallest useful firmware, as a team would write it: tables decoded from an image into a
//! `static` in `.bss`, the unit's state a `static` built by a `const fn`, a panic handler that
//! formats nothing. `scripts/check-firmware-link.sh` builds it without LTO and fails if it links
//! any panic or formatting code (`core::panicking::panic_fmt`, `core::fmt`) or if the tables are
//! not in `.bss`; QEMU's exit status says whether it corrected.
#![no_std]
#![no_main]

use core::hint::black_box;
use core::panic::PanicInfo;

use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
use drift_core::{blob::decode_into, CorrectorState, Model, ModifiedAxisState, Previous, Sample};
use gyrodrift_embedded::{FirmwareTables, MODIFIED};

#[entry]
fn main() -> ! {
    static mut TABLES: FirmwareTables = FirmwareTables::EMPTY;
    static mut STATE: CorrectorState<ModifiedAxisState> = CorrectorState::new();
    static mut KEPT: [Previous; 3] = Previous::NOTHING;

    if decode_into(black_box(MODIFIED), TABLES).is_err() || TABLES.validate().is_err() {
        exit(false);
    }
    let tables: &FirmwareTables = TABLES;
    if STATE
        .power_on_after(tables, black_box([6600.0; 3]), KEPT)
        .is_err()
    {
        exit(false);
    }
    let mut corrected = true;
    for second in 0..120_u32 {
        let sample = Sample {
            since_power_on_ms: second.saturating_mul(1000),
            rate_dps: black_box([0.01; 3]),
            temperature_raw: black_box([6600.0 + second as f32; 3]),
        };
        let output = STATE.correct(tables, &sample);
        corrected &= output.corrected_dps.iter().all(|rate| rate.is_finite());
    }
    STATE.keep(tables, KEPT);
    exit(corrected && KEPT.iter().all(|kept| kept.switch_off_celsius.is_finite()))
}

fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

#[panic_handler]
fn panic(_: &PanicInfo) -> ! {
    exit(false)
}
