//! Flash footprint probe (correct): `scripts/embedded-report.sh` compares the `.text` of
//! footprint_base (runtime only), footprint_decode (+ image decoder and validation) and
//! footprint_correct (+ corrector), so each part's code size is a difference of two builds.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
#[allow(unused_imports)]
use drift_core::{blob::decode_into, Corrector, Sample};
#[allow(unused_imports)]
use gyrodrift_embedded::{FirmwareTables, MODIFIED};
use panic_semihosting as _;

#[entry]
fn main() -> ! {
    static mut TABLES: FirmwareTables = FirmwareTables::EMPTY;
    let image = black_box(MODIFIED);
    if decode_into(image, TABLES).is_ok() {
        let tables: &FirmwareTables = TABLES;
        if let Ok(mut corrector) = Corrector::new(tables) {
            let _ = black_box(corrector.power_on(black_box([6600.0; 3])));
            let sample: Sample = black_box(Sample::default());
            black_box(corrector.correct(&sample));
        }
    }
    debug::exit(debug::EXIT_SUCCESS);
    #[allow(clippy::empty_loop)]
    loop {}
}
