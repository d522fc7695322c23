//! The stillness learner's test vectors' file format (`testdata/stillness-vectors.json`), shared
//! with the embedded firmware's build script: floats as their bits, so the file says exactly what
//! each must be.

use serde::{Deserialize, Serialize};

/// The file: the cases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StillnessVectors {
    /// The cases.
    pub cases: Vec<StillnessCase>,
}

/// One run of a learner: its settings, its inputs, and what it must return for each gyro sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StillnessCase {
    /// Name.
    pub name: String,
    /// `StillnessSettings` in field order (sample rate, accelerometer rate, rate threshold, rate
    /// SD threshold, acceleration SD threshold, variance time constant, still-for, time
    /// constant), f32 bits.
    pub settings: [u32; 8],
    /// The offset the learner starts from (`set_offset`), °/s (f32 bits).
    pub start_offset: [u32; 3],
    /// An accelerometer reading goes in before every `accel_every`-th gyro sample (the first
    /// before sample 0); 0: no accelerometer.
    pub accel_every: u32,
    /// Accelerometer readings, g (f32 bits).
    pub accel: Vec<[u32; 3]>,
    /// Gyro samples, °/s (f32 bits).
    pub rate: Vec<[u32; 3]>,
    /// Per gyro sample, the rate less the learned offset, °/s (f32 bits).
    pub expected: Vec<[u32; 3]>,
    /// Per gyro sample: bit 0 still, bit 1 learning.
    pub states: Vec<u8>,
    /// The offset learned after the last sample, °/s (f32 bits).
    pub final_offset: [u32; 3],
}
