//! Shared by drift-core's integration tests.
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::cast_possible_truncation,
    missing_docs
)]

// The shared vectors are JSON and carry firmware images: they need the `serde` feature. The
// fixture does not, so the fault, extension and property tests also run without it
// (`cargo test -p drift-core --no-default-features`).
#[cfg(feature = "serde")]
pub mod cases;
pub mod fixture;
#[cfg(feature = "serde")]
pub mod format;
#[cfg(feature = "serde")]
pub mod legacy;
