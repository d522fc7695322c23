//! cargo-fuzz target `blob`: the body is `drift_fuzz::blob::run` (see crates/drift-fuzz).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drift_fuzz::blob::run(data));
