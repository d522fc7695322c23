//! cargo-fuzz target `recording`: the body is `drift_fuzz::recording::run` (see crates/drift-fuzz).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drift_fuzz::recording::run(data));
