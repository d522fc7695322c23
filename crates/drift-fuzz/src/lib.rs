//! The bodies of gyrodrift's fuzz targets, one function per target.
//!
//! `fuzz/` (cargo-fuzz, nightly) calls these from `fuzz_target!`; `tests/replay.rs` (stable,
//! part of `cargo test --workspace`) runs every committed corpus file through the same functions,
//! so a corpus entry that once found a bug keeps guarding against it without nightly. Each
//! function panics only when an invariant is broken: that is what the fuzzer reports.

pub mod blob;
pub mod corrector;
pub mod csv;
pub mod models;
pub mod recording;
pub mod seeds;

/// A target's body: runs one input, panics only on a broken invariant.
pub type Target = fn(&[u8]);

/// Every target by its cargo-fuzz name (the folder of its corpus under `fuzz/corpus/`).
pub const TARGETS: [(&str, Target); 4] = [
    ("blob", blob::run),
    ("recording", recording::run),
    ("csv", csv::run),
    ("corrector", corrector::run),
];
