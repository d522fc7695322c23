//! Shared by the firmware binaries: the embedded test vectors, the firmware's table capacities and
//! a stack-use probe.
#![no_std]

use drift_core::{
    ModifiedTables, Previous, RecommendedTables, StillnessLearner, StillnessSettings, SwitchOn,
    Uncertainty,
};

pub mod stack;

/// Table capacities of this firmware: 8 reference times, 3 ambients, 16 curves per ambient (the
/// realistic table `docs/embedded.md` reports on).
pub type FirmwareTables = ModifiedTables<8, 3, 16>;

/// The recommended model at the same capacities.
pub type FirmwareRecommended = RecommendedTables<8, 3, 16>;

/// Which model a vector case runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelName {
    /// The paper's method.
    Modified,
    /// The paper's standard (Lagrange) calibration.
    Standard,
    /// The 3rd-order polynomial baseline.
    ThirdOrder,
    /// The paper's tables plus the extended model's extra terms.
    Extended,
    /// The paper's tables with stage 3 keyed by heating history (residual heat at switch-on).
    ByHistory,
    /// The paper's tables with warm starts' initial bias.
    WarmStarted,
    /// The paper's drift correction with the turn-on bias fitted across activations.
    Recommended,
}

/// One test-vector case (see `testdata/vectors.json`).
pub struct Case {
    /// Case name.
    pub name: &'static str,
    /// Model to run.
    pub model: ModelName,
    /// Raw switch-on temperatures (f32 bits), if the case powers on.
    pub switch_on_raw: Option<[u32; 3]>,
    /// What was kept of the previous activation, per axis `[ambient °C, switch-off °C]` (f32
    /// bits): when present, the case starts with `power_on_after` rather than `power_on`.
    pub previous: Option<[[u32; 2]; 3]>,
    /// Whether power-on must fail.
    pub power_on_fails: bool,
    /// `[ms, rate x y z, raw x y z]`, floats as bits.
    pub samples: &'static [[u32; 7]],
    /// `[corrected x y z, bias x y z, flags x y z]`, floats as bits.
    pub expected: &'static [[u32; 9]],
    /// Auxiliary inputs per sample (floats as bits); empty: corrected without.
    pub aux: &'static [[u32; 4]],
}

/// One σ(t) test-vector case (see `testdata/sigma-vectors.json`).
pub struct SigmaCase {
    /// Case name.
    pub name: &'static str,
    /// Switch-on temperature per axis, °C (f32 bits).
    pub switch_on_celsius: [u32; 3],
    /// What was kept of the previous activation per axis, `[ambient, switch-off]` °C (f32 bits).
    pub previous: Option<[[u32; 2]; 3]>,
    /// Times since switch-on, ms.
    pub times_ms: &'static [u32],
    /// σ per time and axis, °/s (f32 bits).
    pub expected: &'static [[u32; 3]],
}

impl SigmaCase {
    /// σ per time and axis as firmware computes it (f32 bits): the switch-on estimate per axis,
    /// then `Uncertainty::start` and `sigma_dps`.
    pub fn run(&self, uncertainty: &Uncertainty, mut each: impl FnMut(usize, [u32; 3])) {
        let switch_on: [SwitchOn; 3] = core::array::from_fn(|a| {
            let kept = self.previous.map(|p| Previous {
                ambient_celsius: f32::from_bits(p[a][0]),
                switch_off_celsius: f32::from_bits(p[a][1]),
            });
            SwitchOn::estimate(f32::from_bits(self.switch_on_celsius[a]), kept)
        });
        let state = uncertainty.start(&switch_on);
        for (i, &ms) in self.times_ms.iter().enumerate() {
            each(i, uncertainty.sigma_dps(&state, ms).map(f32::to_bits));
        }
    }
}

/// One stillness-learner test-vector case (see `testdata/stillness-vectors.json`).
pub struct StillnessCase {
    /// Case name.
    pub name: &'static str,
    /// `StillnessSettings` in field order, f32 bits.
    pub settings: [u32; 8],
    /// The offset the learner starts from, °/s (f32 bits).
    pub start_offset: [u32; 3],
    /// An accelerometer reading before every `accel_every`-th gyro sample; 0: none.
    pub accel_every: u32,
    /// Accelerometer readings, g (f32 bits).
    pub accel: &'static [[u32; 3]],
    /// Gyro samples, °/s (f32 bits).
    pub rate: &'static [[u32; 3]],
    /// Per gyro sample, the rate less the learned offset (f32 bits).
    pub expected: &'static [[u32; 3]],
    /// Per gyro sample: bit 0 still, bit 1 learning.
    pub states: &'static [u8],
    /// The offset learned after the last sample (f32 bits).
    pub final_offset: [u32; 3],
}

impl StillnessCase {
    /// The learner's settings.
    pub fn settings(&self) -> StillnessSettings {
        StillnessSettings::from_array(self.settings.map(f32::from_bits))
    }

    /// Runs the learner over the case's inputs as firmware would: `each(i, rate bits, states)`
    /// per gyro sample; returns the final offset's bits, or `None` if the settings or the start
    /// offset are refused.
    pub fn run(&self, mut each: impl FnMut(usize, [u32; 3], u8)) -> Option<[u32; 3]> {
        let mut learner = StillnessLearner::new(&self.settings()).ok()?;
        learner
            .set_offset(self.start_offset.map(f32::from_bits))
            .ok()?;
        let mut accel = self.accel.iter();
        for (i, rate) in self.rate.iter().enumerate() {
            if self.accel_every > 0 && (i as u32) % self.accel_every == 0 {
                if let Some(a) = accel.next() {
                    learner.accelerometer(a.map(f32::from_bits));
                }
            }
            let out = learner.update(rate.map(f32::from_bits));
            each(
                i,
                out.rate_dps.map(f32::to_bits),
                u8::from(out.still) | (u8::from(out.learning) << 1),
            );
        }
        Some(learner.offset_dps().map(f32::to_bits))
    }
}

impl Case {
    /// The case's kept previous activation, as drift-core takes it.
    pub fn kept(&self) -> Option<[Previous; 3]> {
        self.previous.map(|kept| {
            kept.map(|[ambient, off]| Previous {
                ambient_celsius: f32::from_bits(ambient),
                switch_off_celsius: f32::from_bits(off),
            })
        })
    }
}

include!(concat!(env!("OUT_DIR"), "/vectors.rs"));
