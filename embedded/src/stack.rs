//! Stack-use probe by painting: fill the stack below the caller with a pattern, run the code under
//! test, then find the deepest word that changed.

use core::ptr::{read_volatile, write_volatile};

const PATTERN: u32 = 0x5AA5_C33C;
/// How deep below the caller's stack pointer to paint, bytes.
pub const DEPTH: usize = 256 * 1024;
/// Words just below the stack pointer left unpainted (the probe's own use).
const MARGIN: usize = 32;

/// A painted stack region, measured relative to the stack pointer at `paint`.
pub struct Painted {
    top: usize,
}

/// Paints the region below the current stack pointer. Inlined, so "current" is the caller's.
#[inline(always)]
pub fn paint() -> Painted {
    let top = cortex_m::register::msp::read() as usize;
    let mut address = top - DEPTH;
    while address < top - MARGIN {
        // SAFETY: the region lies below the live stack frames of this single-threaded program,
        // inside the 4 MiB RAM of the board, and nothing else uses it until the code under test.
        unsafe { write_volatile(address as *mut u32, PATTERN) };
        address += 4;
    }
    Painted { top }
}

impl Painted {
    /// Bytes of stack used below the painting point since `paint` (resolution 4 bytes; at least
    /// `MARGIN`).
    pub fn used(&self) -> usize {
        let mut address = self.top - DEPTH;
        // SAFETY: reads the same painted region.
        while address < self.top - MARGIN
            && unsafe { read_volatile(address as *const u32) } == PATTERN
        {
            address += 4;
        }
        self.top - address
    }
}
