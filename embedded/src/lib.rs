//! Shared by the firmware binaries: the embedded test vectors, the firmware's table capacities and
//! a stack-use probe.
#![no_std]

use drift_core::ModifiedTables;

pub mod stack;

/// Table capacities of this firmware: 8 reference times, 3 ambients, 16 curves per ambient (the
/// realistic table `docs/embedded.md` reports on).
pub type FirmwareTables = ModifiedTables<8, 3, 16>;

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
}

/// One test-vector case (see `testdata/vectors.json`).
pub struct Case {
    /// Case name.
    pub name: &'static str,
    /// Model to run.
    pub model: ModelName,
    /// Raw switch-on temperatures (f32 bits), if the case powers on.
    pub switch_on_raw: Option<[u32; 3]>,
    /// Whether power-on must fail.
    pub power_on_fails: bool,
    /// `[ms, rate x y z, raw x y z]`, floats as bits.
    pub samples: &'static [[u32; 7]],
    /// `[corrected x y z, bias x y z, flags x y z]`, floats as bits.
    pub expected: &'static [[u32; 9]],
    /// Auxiliary inputs per sample (floats as bits); empty: corrected without.
    pub aux: &'static [[u32; 4]],
}

include!(concat!(env!("OUT_DIR"), "/vectors.rs"));
