//! The language-neutral test-vector file (`testdata/vectors.json`): its serde shape.
//!
//! Shared by drift-core's tests (which write and check it) and the firmware's build script (which
//! embeds it). Every float in a case is stored as its IEEE-754 bit pattern (`u32`), so NaN and
//! infinity survive JSON and every reader compares bit for bit.

use serde::{Deserialize, Serialize};

/// The whole file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VectorFile {
    /// Always `"gyrodrift-test-vectors"`.
    pub format: String,
    /// Version of this file's shape.
    pub version: u32,
    /// What the file is and how to read it.
    pub description: Vec<String>,
    /// The models the cases run, by name.
    pub models: Vec<NamedModel>,
    /// The cases.
    pub cases: Vec<Case>,
}

/// One model: its firmware image (the canonical, bit-exact form) and its JSON form (for people).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedModel {
    /// Name the cases refer to.
    pub name: String,
    /// `"modified"` or `"polynomial"`.
    pub kind: String,
    /// The firmware table image, lowercase hex.
    pub image_hex: String,
    /// The same model as drift-core's serde JSON.
    pub tables: serde_json::Value,
}

/// One activation: switch-on, then samples in order, each with its expected output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Case {
    /// Short name.
    pub name: String,
    /// What the case exercises.
    pub description: String,
    /// Name of the model in `models`.
    pub model: String,
    /// Raw switch-on temperature per axis (f32 bits); `null` means: samples arrive without any
    /// `power_on`.
    pub switch_on_raw: Option<[u32; 3]>,
    /// What was kept of the previous activation, per axis `[ambient °C, switch-off °C]` (f32
    /// bits): when present, the case starts with `power_on_after(switch_on_raw, previous)` rather
    /// than `power_on` (tables keyed by heating history read it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub previous: Option<[[u32; 2]; 3]>,
    /// Whether `power_on` must fail (then the samples pass through, flagged not powered on).
    pub power_on_fails: bool,
    /// Samples: `[since_power_on_ms, rate x, y, z, temperature_raw x, y, z]` (floats as bits).
    pub samples: Vec<[u32; 7]>,
    /// Expected outputs: `[corrected x, y, z, bias x, y, z, flags x, y, z]` (floats as bits).
    pub expected: Vec<[u32; 9]>,
    /// Auxiliary inputs per sample (floats as bits), for the extended model: when present, each
    /// sample is corrected with `correct_with_aux`; when absent, with `correct`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aux: Vec<[u32; 4]>,
}
