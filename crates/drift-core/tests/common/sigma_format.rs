//! The σ(t) test vectors' file format (`testdata/sigma-vectors.json`), shared with the embedded
//! firmware's build script: floats as their bits, so the file says exactly what each must be.

use serde::{Deserialize, Serialize};

/// The file: one σ(t) section and the cases run on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SigmaVectors {
    /// The firmware σ(t) section, hex.
    pub section_hex: String,
    /// The cases.
    pub cases: Vec<SigmaCase>,
}

/// One activation: its switch-on, what was kept before it, and σ at each time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SigmaCase {
    /// Name.
    pub name: String,
    /// Switch-on temperature per axis, °C (f32 bits).
    pub switch_on_celsius: [u32; 3],
    /// What was kept of the previous activation per axis, `[ambient, switch-off]` °C (f32 bits);
    /// none: nothing kept.
    pub previous: Option<[[u32; 2]; 3]>,
    /// Times since switch-on, ms.
    pub times_ms: Vec<u32>,
    /// σ per time and axis, °/s (f32 bits).
    pub expected: Vec<[u32; 3]>,
}
