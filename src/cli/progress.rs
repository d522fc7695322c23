//! Progress bars for long steps.

use std::sync::Mutex;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// A bar per named step, created when the step first reports; `quiet` hides them all. As the
/// library's [`drift_recording::Progress`] it only listens: Ctrl-C ends the process
/// (`super::interrupt`).
pub struct Steps {
    quiet: bool,
    current: Mutex<Option<(String, ProgressBar)>>,
}

impl Steps {
    /// New, with no step started.
    pub fn new(quiet: bool) -> Self {
        Self {
            quiet,
            current: Mutex::new(None),
        }
    }

    /// Reports `done` of `total` for `step`.
    pub fn update(&self, step: &str, done: u64, total: u64) {
        let Ok(mut current) = self.current.lock() else {
            return;
        };
        if current.as_ref().is_none_or(|(name, _)| name != step) {
            if let Some((_, bar)) = current.take() {
                bar.finish();
            }
            let bar = if self.quiet {
                ProgressBar::hidden()
            } else {
                ProgressBar::new(total)
            };
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg} ({remaining})",
            ) {
                // "left: –" until one item is done: an estimate from nothing is not one.
                bar.set_style(style.with_key(
                    "remaining",
                    |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = if state.pos() == 0 {
                            write!(w, "left: –")
                        } else {
                            write!(w, "left: about {}", indicatif::HumanDuration(state.eta()))
                        };
                    },
                ));
            }
            // A step of one long item still shows that it runs, and for how long.
            bar.enable_steady_tick(Duration::from_millis(200));
            bar.set_message(step.to_owned());
            *current = Some((step.to_owned(), bar));
        }
        if let Some((_, bar)) = current.as_ref() {
            bar.set_length(total);
            bar.set_position(done);
        }
    }

    /// Finishes the last bar.
    pub fn finish(&self) {
        if let Ok(mut current) = self.current.lock() {
            if let Some((_, bar)) = current.take() {
                bar.finish();
            }
        }
    }
}

impl drift_recording::Progress for Steps {
    fn report(&self, step: &str, done: u64, total: u64) -> std::ops::ControlFlow<()> {
        self.update(step, done, total);
        std::ops::ControlFlow::Continue(())
    }
}
