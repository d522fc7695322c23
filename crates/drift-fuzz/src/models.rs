//! Valid models for the corrector target: the shared test vectors' models
//! (`testdata/vectors.json`) that the target drives, decoded from their firmware images once.

use std::sync::OnceLock;

use drift_core::blob::decode;
use drift_core::{ModifiedTables, PolynomialTables};

const VECTORS: &str = include_str!("../../../testdata/vectors.json");

/// The shared vectors' models: the paper's tables, the two polynomial baselines, the paper's
/// tables with stage 3 keyed by heating history, the paper's tables with warm starts' initial
/// bias, and the extended model (four extra terms, the rate filter started at the rate at
/// switch-on).
pub struct Models {
    /// The modified (paper's) tables.
    pub modified: ModifiedTables,
    /// The standard (Lagrange) baseline.
    pub standard: PolynomialTables,
    /// The 3rd-order least-squares baseline.
    pub third_order: PolynomialTables,
    /// The paper's tables with stage 3 keyed by heating history (`power_on_after`, `keep`).
    pub by_history: ModifiedTables,
    /// The paper's tables with the initial bias of warm starts (`power_on_after`, `keep`).
    pub warm_started: ModifiedTables,
    /// The extended model: its rate filter starts from what `power_on_after` was given.
    pub extended: ModifiedTables,
}

fn unhex(hex: &str) -> Vec<u8> {
    hex.as_bytes()
        .chunks(2)
        .filter_map(|pair| {
            std::str::from_utf8(pair)
                .ok()
                .and_then(|p| u8::from_str_radix(p, 16).ok())
        })
        .collect()
}

/// The firmware images of the shared vectors' models, by name (`modified`, `standard`,
/// `third_order`, `extended`, `by_history`): the seeds of the blob target.
pub fn images() -> Vec<(String, Vec<u8>)> {
    let file: serde_json::Value = serde_json::from_str(VECTORS).unwrap_or_default();
    file["models"]
        .as_array()
        .map(|models| {
            models
                .iter()
                .map(|m| {
                    let name = m["name"].as_str().unwrap_or_default().to_owned();
                    (name, unhex(m["image_hex"].as_str().unwrap_or_default()))
                })
                .collect()
        })
        .unwrap_or_default()
}

fn image(name: &str) -> Vec<u8> {
    images()
        .into_iter()
        .find(|(n, _)| n == name)
        .map(|(_, bytes)| bytes)
        .unwrap_or_default()
}

/// The models, decoded once per process. Panics if the committed vectors do not decode (a
/// broken checkout, not a fuzz finding: the replay test fails first).
pub fn models() -> &'static Models {
    static MODELS: OnceLock<Models> = OnceLock::new();
    MODELS.get_or_init(|| {
        let bad = |name: &str, e: drift_core::blob::BlobError| -> ! {
            panic!("testdata/vectors.json: model {name} does not decode: {e}")
        };
        Models {
            modified: decode(&image("modified")).unwrap_or_else(|e| bad("modified", e)),
            standard: decode(&image("standard")).unwrap_or_else(|e| bad("standard", e)),
            third_order: decode(&image("third_order")).unwrap_or_else(|e| bad("third_order", e)),
            by_history: decode(&image("by_history")).unwrap_or_else(|e| bad("by_history", e)),
            warm_started: decode(&image("warm_started")).unwrap_or_else(|e| bad("warm_started", e)),
            extended: decode(&image("extended")).unwrap_or_else(|e| bad("extended", e)),
        }
    })
}
