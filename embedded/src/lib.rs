//! Shared by the firmware binaries: the embedded test vectors, the firmware's table capacities and
//! a stack-use probe.
#![no_std]

use drift_core::{ModifiedTables, Previous, RecommendedTables, SwitchOn, Uncertainty};

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
