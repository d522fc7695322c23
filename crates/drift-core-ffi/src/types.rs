//! The values that cross the boundary, laid out for C, and their sizes.

use drift_core::{Flags, Output, Previous, Sample, AUX_INPUTS, AXES, MISSING_TEMPERATURE};

// Literals, so the header carries numbers; the compiler checks them against drift-core's.
/// Gyro axes per unit (X, Y, Z).
pub const GYRODRIFT_AXES: usize = 3;
/// Auxiliary inputs `gyrodrift_correct_with_aux` takes (the extended model's terms read them).
pub const GYRODRIFT_AUX_INPUTS: usize = 4;
/// The raw temperature count meaning "no reading this sample" (`INT16_MIN`), for firmware that
/// converts 16-bit counts to `temperature_raw` with `gyrodrift_sample_from_counts`.
pub const GYRODRIFT_MISSING_TEMPERATURE: i16 = -32_768;

const _: () = {
    assert!(GYRODRIFT_AXES == AXES);
    assert!(GYRODRIFT_AUX_INPUTS == AUX_INPUTS);
    assert!(GYRODRIFT_MISSING_TEMPERATURE == MISSING_TEMPERATURE);
};
/// Bytes of a `gyrodrift_context`: the default profile, up to 8
/// reference times, 3 ambients and 16 curves per ambient per axis (the realistic table of
/// docs/embedded.md), on a 32-bit MCU. The compiler checks it holds the context (12 268 bytes on
/// `thumbv7em`); the tables' counts are pointer-sized, so a 64-bit host needs more.
#[cfg(not(target_pointer_width = "64"))]
pub const GYRODRIFT_CONTEXT_BYTES: usize = 12_544;
/// On a 64-bit host (`__LP64__` in C): 12 992 bytes used.
#[cfg(target_pointer_width = "64")]
pub const GYRODRIFT_CONTEXT_BYTES: usize = 13_312;
/// Bytes of a `gyrodrift_large_context`: up to 16 reference
/// times, 6 ambients and 32 curves per ambient, on a 32-bit MCU (83 968 bytes used on
/// `thumbv7em`).
#[cfg(not(target_pointer_width = "64"))]
pub const GYRODRIFT_LARGE_CONTEXT_BYTES: usize = 84_480;
/// On a 64-bit host: 86 528 bytes used.
#[cfg(target_pointer_width = "64")]
pub const GYRODRIFT_LARGE_CONTEXT_BYTES: usize = 87_040;

/// One 3-axis sample, as drift-core's `Sample`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GyrodriftSample {
    /// Time since switch-on, milliseconds.
    pub since_power_on_ms: u32,
    /// Measured angular rate per axis, °/s.
    pub rate_dps: [f32; GYRODRIFT_AXES],
    /// Raw temperature reading per axis, sensor units (NaN: no reading).
    pub temperature_raw: [f32; GYRODRIFT_AXES],
}

impl From<&GyrodriftSample> for Sample {
    fn from(sample: &GyrodriftSample) -> Self {
        Self {
            since_power_on_ms: sample.since_power_on_ms,
            rate_dps: sample.rate_dps,
            temperature_raw: sample.temperature_raw,
        }
    }
}

/// The corrector's answer for one sample, as drift-core's `Output`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GyrodriftOutput {
    /// Rate with the estimated zero drift removed, °/s.
    pub corrected_dps: [f32; GYRODRIFT_AXES],
    /// The zero drift removed, °/s.
    pub bias_dps: [f32; GYRODRIFT_AXES],
    /// Per axis, what was clamped, held or passed through (drift-core's `Flags` bits).
    pub flags: [u16; GYRODRIFT_AXES],
}

impl From<Output> for GyrodriftOutput {
    fn from(output: Output) -> Self {
        Self {
            corrected_dps: output.corrected_dps,
            bias_dps: output.bias_dps,
            flags: output.flags.map(|Flags(bits)| bits),
        }
    }
}

/// What firmware keeps of an activation across power-off, per axis (retained RAM or flash), as
/// drift-core's `Previous`. Before the first activation: both NaN.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyrodriftPrevious {
    /// The ambient estimated for that activation, °C.
    pub ambient_celsius: f32,
    /// Its last good temperature reading, °C.
    pub switch_off_celsius: f32,
}

impl From<GyrodriftPrevious> for Previous {
    fn from(kept: GyrodriftPrevious) -> Self {
        Self {
            ambient_celsius: kept.ambient_celsius,
            switch_off_celsius: kept.switch_off_celsius,
        }
    }
}

impl From<Previous> for GyrodriftPrevious {
    fn from(kept: Previous) -> Self {
        Self {
            ambient_celsius: kept.ambient_celsius,
            switch_off_celsius: kept.switch_off_celsius,
        }
    }
}
