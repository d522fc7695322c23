//! A firmware that corrects a MEMS gyroscope's temperature drift with drift-core: the tables
//! decoded from their flash image into a `static` in `.bss`, checked against the sensor's own
//! settings, the unit's state a `static` built by a `const fn`, one sample corrected per reading,
//! and what the next switch-on needs kept before power-off. `cargo run --release` runs it on QEMU;
//! docs/embedded.md ("Start your firmware from this") says what to change for a part.
#![no_std]
#![no_main]

use core::panic::PanicInfo;

use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
use drift_core::blob::{self, BlobError};
use drift_core::{
    CorrectorState, Model, ModifiedAxisState, ModifiedTables, Previous, Sample, SensorSettings,
    Settings,
};

/// The tables' capacities: reference times, ambients, curves per ambient. An image that needs
/// more is refused with the capacity it needs (`BlobError::Capacity`).
type Tables = ModifiedTables<8, 3, 16>;

/// Where `gyrodrift export image --address` provisions each unit's image on your part, and the
/// sector's size; the image says its own length, and the erased rest of the sector reads 0xFF.
/// On hardware the sector is read in place:
/// `unsafe { core::slice::from_raw_parts(IMAGE_ADDRESS as *const u8, IMAGE_SECTOR_BYTES) }`.
#[allow(dead_code)]
const IMAGE_ADDRESS: usize = 0x0806_0000;
#[allow(dead_code)]
const IMAGE_SECTOR_BYTES: usize = 16 * 1024;

/// QEMU has no provisioned sector: the repository's test image stands in for it.
static SECTOR: &[u8] = include_bytes!("../../../testdata/image-v3-modified.bin");

/// The temperature sensor as its data sheet states it (the test image's: 256 LSB/°C, reading 0 at
/// 25 °C): the image's tables must have been fitted on readings of this scale.
const SENSOR: SensorSettings = SensorSettings {
    raw_per_celsius: 256.0,
    raw_at_zero_celsius: -6400.0,
    sample_rate_hz: 1000.0,
    stuck_after_seconds: 2.0,
    ..SensorSettings::DEFAULT
};

/// Samples this demonstration corrects, and their period.
const SAMPLES: u32 = 2000;
const PERIOD_MS: u32 = 1;

#[entry]
fn main() -> ! {
    static mut TABLES: Tables = Tables::EMPTY;
    static mut STATE: CorrectorState<ModifiedAxisState> = CorrectorState::new();
    // What was kept of the previous activation: in retained RAM or flash on your part.
    static mut KEPT: [Previous; 3] = Previous::NOTHING;

    if load(SECTOR, TABLES).is_err() || !same_scale(&TABLES.settings) {
        // A damaged or foreign image: no correction rather than a wrong one.
        exit(false);
    }
    let tables: &Tables = TABLES;
    if STATE
        .power_on_after(tables, temperature(0).map(f32::from), KEPT)
        .is_err()
    {
        exit(false);
    }
    let mut corrected = true;
    for n in 0..SAMPLES {
        let sample = Sample::from_counts(n * PERIOD_MS, rate(n), temperature(n));
        let output = STATE.correct(tables, &sample);
        corrected &= output.corrected_dps.iter().all(|r| r.is_finite());
    }
    // Before power-off (or periodically, if power can go without warning).
    STATE.keep(tables, KEPT);
    exit(corrected)
}

/// Why no tables were loaded: the image (never written, damaged, another model, too large for
/// [`Tables`]), or tables that do not validate. Report it as your firmware reports faults.
#[allow(dead_code)]
enum LoadError {
    Image(BlobError),
    Tables(drift_core::Error),
}

/// Decodes the image at the start of `sector` into `tables` and validates them.
fn load(sector: &[u8], tables: &mut Tables) -> Result<(), LoadError> {
    let len = blob::image_len(sector).map_err(LoadError::Image)?;
    let image = sector
        .get(..len)
        .ok_or(LoadError::Image(BlobError::Truncated {
            needed: len,
            found: sector.len(),
        }))?;
    blob::decode_into(image, tables).map_err(LoadError::Image)?;
    tables.validate().map_err(LoadError::Tables)
}

/// Whether the tables convert raw readings as this sensor reports them.
fn same_scale(settings: &Settings) -> bool {
    match Settings::from_sensor(&SENSOR) {
        Ok(sensor) => {
            sensor.raw_per_celsius == settings.raw_per_celsius
                && sensor.raw_at_zero_celsius == settings.raw_at_zero_celsius
        }
        Err(_) => false,
    }
}

/// The gyroscope's rate, °/s: your driver's reading.
fn rate(_n: u32) -> [f32; 3] {
    [0.01, -0.02, 0.005]
}

/// The temperature sensor's counts: your driver's reading (here a unit switched on at 30 °C and
/// warming by 2 °C).
fn temperature(n: u32) -> [i16; 3] {
    let warmed = (512 * n / SAMPLES) as i16;
    [1280 + warmed; 3]
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
