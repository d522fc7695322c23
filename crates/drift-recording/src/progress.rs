//! How a long call (simulating, reading, fitting, evaluating, diagnosing) reports how far it got
//! and learns that it should stop. The loops ask between units of work — a file, an activation,
//! a block of samples — never per sample, so a stop takes effect within one unit; a stopped call
//! returns its [`Interrupted`] error after removing what it had started to write.
//!
//! A closure `Fn(&str, u64, u64)` is a [`Progress`] that only listens (a progress bar); a type of
//! its own implements [`Progress::report`] to stop the call too (Python's Ctrl-C).

use std::ops::ControlFlow;

/// Told how far a long call got; answers whether it should go on.
pub trait Progress: Sync {
    /// `done` of `total` units of `step` are finished (`done` never decreases within a step);
    /// [`ControlFlow::Break`] asks the call to stop.
    fn report(&self, step: &str, done: u64, total: u64) -> ControlFlow<()>;

    /// [`Progress::report`] as a `Result`, for `?` in the loops.
    fn check(&self, step: &str, done: u64, total: u64) -> Result<(), Interrupted> {
        match self.report(step, done, total) {
            ControlFlow::Continue(()) => Ok(()),
            ControlFlow::Break(()) => Err(Interrupted),
        }
    }
}

impl<F: Fn(&str, u64, u64) + Sync> Progress for F {
    fn report(&self, step: &str, done: u64, total: u64) -> ControlFlow<()> {
        self(step, done, total);
        ControlFlow::Continue(())
    }
}

/// A [`Progress`] for a call inside one unit of an outer step: whatever the inner call reports,
/// the outer step is told its position again (`done` of `total` of `step`), so a bar does not
/// move, and the inner call stops when the outer [`Progress`] asks to.
#[derive(Clone, Copy)]
pub struct Within<'a> {
    /// The outer call's progress.
    pub outer: &'a dyn Progress,
    /// Its step.
    pub step: &'a str,
    /// Units of it done.
    pub done: u64,
    /// Its units.
    pub total: u64,
}

impl Progress for Within<'_> {
    fn report(&self, _: &str, _: u64, _: u64) -> ControlFlow<()> {
        self.outer.report(self.step, self.done, self.total)
    }
}

/// A [`Progress`] that neither listens nor stops.
pub const QUIET: &dyn Progress = &|_: &str, _: u64, _: u64| {};

/// A long call was stopped by its [`Progress`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    struct StopAt(u64);

    impl Progress for StopAt {
        fn report(&self, _: &str, done: u64, _: u64) -> ControlFlow<()> {
            if done >= self.0 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    }

    #[test]
    fn a_closure_listens_and_never_stops_and_a_stopper_stops() {
        let seen = AtomicU64::new(0);
        let listen = |_: &str, done: u64, _: u64| {
            seen.store(done, Ordering::Relaxed);
        };
        let progress: &dyn Progress = &listen;
        assert_eq!(progress.check("reading", 7, 9), Ok(()));
        assert_eq!(seen.load(Ordering::Relaxed), 7);
        assert_eq!(QUIET.check("reading", 1, 1), Ok(()));
        let stop: &dyn Progress = &StopAt(3);
        assert_eq!(stop.check("reading", 2, 9), Ok(()));
        assert_eq!(stop.check("reading", 3, 9), Err(Interrupted));
        let inner = Within {
            outer: stop,
            step: "fitting",
            done: 4,
            total: 9,
        };
        assert_eq!(inner.check("reading", 0, 9), Err(Interrupted));
    }
}
