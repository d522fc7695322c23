//! Ctrl-C and progress for the long calls. The work runs on a thread of its own with the GIL
//! released and reports to a [`drift_recording::Progress`] between units of work; the calling
//! thread, the interpreter's, wakes every [`POLL`], takes the GIL briefly, runs Python's signal
//! handlers (only the main thread can) and the caller's `progress` callable. An exception there —
//! `KeyboardInterrupt` from Ctrl-C, or one the callable raised — makes the work stop at its next
//! check; its writer removes what it had started (a staging folder, a temporary file), and the
//! exception is raised once the work has returned.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

use drift_recording::Progress;
use pyo3::prelude::*;

use crate::arrays::describe;
use crate::errors::Error;

/// How often the interpreter's thread looks at signals and reports progress.
const POLL: Duration = Duration::from_millis(100);

/// Stack of the work's thread, bytes (reserved address space, not memory in use): the fits' and
/// the diagnosis loop's host types are values of hundreds of KB.
pub const WORK_STACK_BYTES: usize = 256 << 20;

/// What the work reported last, and whether it must stop.
#[derive(Default)]
struct Hook {
    stop: AtomicBool,
    latest: Mutex<Option<(String, u64, u64)>>,
}

impl Progress for Hook {
    fn report(&self, step: &str, done: u64, total: u64) -> ControlFlow<()> {
        if let Ok(mut latest) = self.latest.lock() {
            // Within a step the count only grows, whichever thread reports first.
            let grows = match latest.as_ref() {
                Some((last, seen, _)) => last != step || done >= *seen,
                None => true,
            };
            if grows {
                *latest = Some((step.to_owned(), done, total));
            }
        }
        if self.stop.load(Ordering::Relaxed) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Whether the work has returned (or panicked), told to the waiting thread.
#[derive(Default)]
struct Over {
    over: Mutex<bool>,
    signal: Condvar,
}

impl Over {
    /// Waits up to `timeout`; whether the work is over.
    fn wait(&self, timeout: Duration) -> bool {
        let Ok(over) = self.over.lock() else {
            return true;
        };
        match self.signal.wait_timeout_while(over, timeout, |over| !*over) {
            Ok((over, _)) => *over,
            Err(_) => true,
        }
    }
}

/// Tells [`Over`] when dropped: at the work's return, or while a panic unwinds it.
struct Finish<'a>(&'a Over);

impl Drop for Finish<'_> {
    fn drop(&mut self) {
        if let Ok(mut over) = self.0.over.lock() {
            *over = true;
        }
        self.0.signal.notify_all();
    }
}

/// The `progress` argument: `None` or a callable, checked before any work starts.
pub fn callable<'py>(
    progress: Option<&Bound<'py, PyAny>>,
) -> Result<Option<Bound<'py, PyAny>>, Error> {
    match progress {
        None => Ok(None),
        Some(p) if p.is_none() => Ok(None),
        Some(p) if p.is_callable() => Ok(Some(p.clone())),
        Some(p) => Err(Error::Input(format!(
            "`progress` must be None or a callable taking (step: str, done: int, total: int), got {}",
            describe(p)
        ))),
    }
}

/// Runs `work` off the interpreter's thread with the GIL released, honouring Ctrl-C within
/// [`POLL`] plus one unit of work, and calling `progress(step, done, total)` (at most once per
/// [`POLL`], when the count moved). `work`'s result, or the exception that stopped it.
pub fn run<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&dyn Progress) -> T + Send,
) -> PyResult<T> {
    let hook = Hook::default();
    let over = Over::default();
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("gyrodrift-work".into())
            .stack_size(WORK_STACK_BYTES)
            .spawn_scoped(scope, || {
                let _finish = Finish(&over);
                work(&hook)
            })
            .map_err(|e| Error::Input(format!("internal: starting the work's thread: {e}")))?;
        let mut raised: Option<PyErr> = None;
        let mut shown = None;
        loop {
            let finished = py.detach(|| over.wait(POLL));
            if raised.is_none() {
                // Once the work is over, a pending signal is the interpreter's to raise.
                if let Err(error) = poll(py, &hook, progress, &mut shown, !finished) {
                    hook.stop.store(true, Ordering::Relaxed);
                    raised = Some(error);
                }
            }
            if finished {
                break;
            }
        }
        let out = worker
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        match raised {
            Some(error) => Err(error),
            None => Ok(out),
        }
    })
}

/// One look from the interpreter's thread: signal handlers (with `signals`), then the caller's
/// callable if the work moved since it was last called.
fn poll(
    py: Python<'_>,
    hook: &Hook,
    progress: Option<&Bound<'_, PyAny>>,
    shown: &mut Option<(String, u64, u64)>,
    signals: bool,
) -> PyResult<()> {
    if signals {
        py.check_signals()?;
    }
    let Some(progress) = progress else {
        return Ok(());
    };
    let latest = hook.latest.lock().ok().and_then(|l| l.clone());
    if latest.is_some() && latest != *shown {
        if let Some((step, done, total)) = &latest {
            progress.call1((step.as_str(), *done, *total))?;
        }
        *shown = latest;
    }
    Ok(())
}
