//! The one rule for simulating into a folder, shared by `gyrodrift simulate` and Python's
//! `gyrodrift.simulate`: an empty (or missing) folder is used; a folder holding a campaign is
//! replaced only when asked to (`force`); anything else is never deleted. It is every writer's
//! rule ([`drift_recording::output_folder`]), with a campaign told by the names it holds.

use std::path::Path;

use drift_recording::output_folder::{Owned, Writer};
use drift_recording::{COMPLETION_MARKER, RECORDINGS_DIR, TRUTH_DIR};

pub use drift_recording::output_folder::FolderError;

/// What a simulation writes into its output folder, and so what `force` replaces.
pub const WRITTEN: [&str; 3] = [RECORDINGS_DIR, TRUTH_DIR, COMPLETION_MARKER];

/// `simulate` as a writer of output folders.
pub const SIMULATE: Writer = Writer {
    command: "simulate",
    product: "campaign",
    doing: "simulating",
    owned: Owned::Names(&WRITTEN),
};

/// Refuses an output folder holding anything, unless `force`: then removes what an earlier
/// simulation wrote there, and refuses anything else it holds (it is not ours to delete).
pub fn prepare(out: &Path, force: bool, flag: &'static str) -> Result<(), FolderError> {
    drift_recording::output_folder::prepare(out, force, flag, &SIMULATE)
}
