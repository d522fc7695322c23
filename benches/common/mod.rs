//! Shared bench inputs: the demonstration models of the shared test vectors, and a seeded 2-minute
//! activation at 1000 Hz that exercises every stage of the paper's model.

use drift_core::blob::decode;
use drift_core::{ModifiedTables, PolynomialTables, Sample};

const VECTORS: &str = include_str!("../../testdata/vectors.json");

fn image(name: &str) -> Vec<u8> {
    let file: serde_json::Value = serde_json::from_str(VECTORS).expect("vectors");
    let hex = file["models"]
        .as_array()
        .expect("models")
        .iter()
        .find(|m| m["name"] == name)
        .expect("model")["image_hex"]
        .as_str()
        .expect("hex")
        .to_owned();
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex"))
        .collect()
}

/// The paper's tables (3 axes × 3 ambients × 16 curves × 8 reference times).
pub fn modified() -> ModifiedTables {
    decode(&image("modified")).expect("modified image")
}

/// A polynomial baseline by name (`standard` or `third_order`).
pub fn polynomial(name: &str) -> PolynomialTables {
    decode(&image(name)).expect("polynomial image")
}

/// Switch-on raw temperatures: between the 30 and 40 °C ambients (both blended).
pub const SWITCH_ON_RAW: [f32; 3] = [6600.0, 6640.0, 6580.0];

/// 120 000 samples (2 min at 1000 Hz) of a heating unit, with a little seeded noise.
pub fn activation() -> Vec<Sample> {
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
    };
    (0..120_000u32)
        .map(|i| {
            let t = i as f32 / 1000.0;
            let shape = 1.0 - (-t / 60.0).exp();
            Sample {
                since_power_on_ms: i,
                rate_dps: [
                    0.1 + 0.002 * noise(),
                    -0.05 + 0.002 * noise(),
                    0.02 + 0.002 * noise(),
                ],
                temperature_raw: [0, 1, 2].map(|a| {
                    (SWITCH_ON_RAW[a] + 200.0 * (3.5 + a as f32 * 0.5) * shape + noise()).round()
                }),
            }
        })
        .collect()
}
