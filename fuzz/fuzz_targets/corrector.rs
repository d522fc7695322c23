//! cargo-fuzz target `corrector`: the body is `drift_fuzz::corrector::run` (see crates/drift-fuzz).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drift_fuzz::corrector::run(data));
