//! A C interface to drift-core: a static library (`libdrift_core_ffi.a`) and its header
//! (`include/gyrodrift.h`) for firmware written in C.
//!
//! The C side owns all memory: a context per unit, of a fixed capacity profile
//! ([`GYRODRIFT_CONTEXT_BYTES`], [`GYRODRIFT_LARGE_CONTEXT_BYTES`]), usually a `static` (zeroed,
//! in `.bss`). `gyrodrift_init` decodes a table image into it (the paper's tables or the
//! recommended model, whichever the image holds); then, per activation, `gyrodrift_power_on`
//! or `gyrodrift_power_on_after`, `gyrodrift_correct` per sample, `gyrodrift_keep` before
//! power-off. Each call maps onto drift-core's `CorrectorState` method of the same name, so the
//! outputs are drift-core's, bit for bit.
//!
//! Every function returns a [`GyrodriftStatus`] (0: success, negative: what was wrong) and never
//! panics; a null pointer is an error, not a crash.
//!
//! # Why `unsafe` here and nowhere else
//!
//! The workspace forbids `unsafe`. A C boundary cannot do without it: C passes raw pointers, and
//! the context lives in memory C allocated, which Rust must initialise and then borrow. This crate
//! is that boundary and nothing more: each `unsafe` block turns one pointer the caller vouches for
//! into a reference (the conditions are on each function, and a SAFETY comment on each block
//! says why they suffice), and everything past it is drift-core's safe code.
#![cfg_attr(target_os = "none", no_std)]
#![deny(unsafe_op_in_unsafe_fn)]

mod api;
mod context;
mod status;
mod types;

pub use api::*;
pub use context::{GyrodriftContext, GyrodriftLargeContext};
pub use status::GyrodriftStatus;
pub use types::{
    GyrodriftOutput, GyrodriftPrevious, GyrodriftSample, GYRODRIFT_AUX_INPUTS, GYRODRIFT_AXES,
    GYRODRIFT_CONTEXT_BYTES, GYRODRIFT_LARGE_CONTEXT_BYTES, GYRODRIFT_MISSING_TEMPERATURE,
};

/// drift-core never panics (its lints deny every panicking construct), so this is never
/// reached; it formats nothing, so a build without LTO links no `core::fmt` for it.
#[cfg(target_os = "none")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
