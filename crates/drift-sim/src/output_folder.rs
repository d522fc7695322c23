//! The one rule for simulating into a folder, shared by `gyrodrift simulate` and Python's
//! `gyrodrift.simulate`: an empty (or missing) folder is used; a folder holding a campaign is
//! replaced only when asked to (`force`); anything else is never deleted. It is every writer's
//! rule ([`drift_recording::output_folder`]), with a campaign told by the names it holds. Both
//! simulate into a staging folder put in place at the end, so a failed run leaves an earlier
//! campaign as it was, and [`summary_in_place`] makes `summary.json` name the files where they
//! end up.

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

/// Rewrites the paths `summary.json` gives for the files written into `stage` (a
/// [`drift_recording::output_folder::Staged`] folder) as they are once the folder is in place as
/// `out`; the rest of the file keeps its bytes. Returns the rewritten text.
pub fn summary_in_place(stage: &Path, out: &Path) -> Result<String, FolderError> {
    let path = stage.join(COMPLETION_MARKER);
    let io = |action: &'static str| {
        let path = path.clone();
        move |source: std::io::Error| FolderError::Io {
            action,
            path,
            source,
        }
    };
    let text = std::fs::read_to_string(&path).map_err(io("reading"))?;
    // As JSON string contents, with the separator that starts a file's path inside the folder.
    let quoted = |folder: &Path| -> Result<String, std::io::Error> {
        let json = serde_json::to_string(&folder.join("x").display().to_string())
            .map_err(std::io::Error::other)?;
        let inner = json
            .get(1..json.len().saturating_sub(2))
            .unwrap_or_default();
        Ok(format!("\"{inner}"))
    };
    let (from, to) = (
        quoted(stage).map_err(io("reading"))?,
        quoted(out).map_err(io("reading"))?,
    );
    let text = text.replace(&from, &to);
    drift_recording::write_atomic(&path, text.as_bytes()).map_err(io("writing"))?;
    Ok(text)
}
