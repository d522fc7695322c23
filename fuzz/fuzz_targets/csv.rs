//! cargo-fuzz target `csv`: the body is `drift_fuzz::csv::run` (see crates/drift-fuzz).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drift_fuzz::csv::run(data));
