//! What Ctrl-C leaves behind. Every file is written to a temporary beside its target and renamed
//! when whole, and a campaign folder is vouched for by a completion marker written last, so an
//! interrupted command leaves nothing a reader accepts; this also removes the half-written
//! temporaries themselves. A command registers the folders it writes into; on SIGINT (or SIGTERM)
//! this process's temporaries there are deleted and the process exits with status 130. An output
//! written whole into a staging folder ([`stage`]) loses only that folder: the earlier output
//! stays as it was.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Exit status after an interruption (128 + SIGINT, as shells report it).
pub const INTERRUPTED: i32 = 130;

/// Folders a running command writes into.
static FOLDERS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Staging folders of outputs not yet in place: removed whole on an interruption.
static STAGES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Begins writing `writer`'s output for `out` in a staging folder
/// ([`drift_recording::output_folder::Staged`]) that an interruption removes whole.
pub fn stage(
    out: &Path,
    force: bool,
    writer: &drift_recording::output_folder::Writer,
) -> Result<drift_recording::output_folder::Staged, drift_recording::output_folder::FolderError> {
    let staged = drift_recording::output_folder::Staged::begin(out, force, "--force", writer)?;
    if let Ok(mut stages) = STAGES.lock() {
        stages.push(staged.path().to_path_buf());
    }
    Ok(staged)
}

/// Installs the handler (once per process; a second call is a no-op error, ignored).
pub fn install() {
    // Without a handler, Ctrl-C kills the process and the temporaries stay: not fatal, so a
    // platform that refuses the handler still runs the command.
    let _ = ctrlc::set_handler(on_interrupt);
}

/// Registers `folder` (and everything below it) as written by this command.
pub fn watch(folder: &Path) {
    if let Ok(mut folders) = FOLDERS.lock() {
        folders.push(folder.to_path_buf());
    }
}

fn on_interrupt() {
    let stages = STAGES.lock().map(|f| f.clone()).unwrap_or_default();
    for stage in &stages {
        // Renamed first: the command may still be writing into it while this runs.
        let doomed = stage.with_extension("discarded");
        let gone =
            std::fs::rename(stage, &doomed).is_ok() && std::fs::remove_dir_all(&doomed).is_ok();
        // A writer that recreated the folder meanwhile leaves at most what it wrote since.
        let _ = std::fs::remove_dir_all(stage);
        if gone {
            eprintln!(
                "interrupted: removed the unfinished output {}; an earlier output stays as it was",
                stage.display()
            );
        }
    }
    if !stages.is_empty() && FOLDERS.lock().map(|f| f.is_empty()).unwrap_or(true) {
        std::process::exit(INTERRUPTED);
    }
    let folders = FOLDERS.lock().map(|f| f.clone()).unwrap_or_default();
    let pid = std::process::id();
    let mut removed = 0;
    for folder in &folders {
        removed += remove_temporaries(folder, pid, 3);
    }
    let places = folders
        .iter()
        .map(|f| f.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    if folders.is_empty() {
        eprintln!("interrupted");
    } else {
        eprintln!(
            "interrupted: removed {removed} partial file(s) from {places}; what was complete \
             stays, and a campaign folder without summary.json is refused by every reader"
        );
    }
    std::process::exit(INTERRUPTED);
}

/// Whether `name` is one of this process's temporaries: the recording writer's
/// `.<name>.<pid>.tmp` or `write_atomic`'s `<name>.tmp-<pid>-<n>`.
fn is_temporary(name: &str, pid: u32) -> bool {
    name.ends_with(&format!(".{pid}.tmp")) || name.contains(&format!(".tmp-{pid}-"))
}

fn remove_temporaries(folder: &Path, pid: u32, depth: u32) -> usize {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() && depth > 0 {
            removed += remove_temporaries(&path, pid, depth - 1);
        } else if kind.is_file()
            && is_temporary(&entry.file_name().to_string_lossy(), pid)
            && std::fs::remove_file(&path).is_ok()
        {
            removed += 1;
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_this_process_temporaries_are_recognised() {
        assert!(is_temporary(
            ".GIU-01_sp+30.0C_protocol.mcap.4242.tmp",
            4242
        ));
        assert!(is_temporary("report.md.tmp-4242-7", 4242));
        assert!(!is_temporary(
            ".GIU-01_sp+30.0C_protocol.mcap.4243.tmp",
            4242
        ));
        assert!(!is_temporary("GIU-01_sp+30.0C_protocol.mcap", 4242));
        assert!(!is_temporary("summary.json", 4242));
    }

    #[test]
    fn removes_temporaries_below_a_folder_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let nested = dir.path().join("recordings");
        std::fs::create_dir(&nested).unwrap();
        for name in [".a.mcap.7.tmp", "a.mcap", ".b.mcap.8.tmp"] {
            std::fs::write(nested.join(name), b"x").unwrap();
        }
        std::fs::write(dir.path().join("summary.json.tmp-7-0"), b"x").unwrap();
        assert_eq!(remove_temporaries(dir.path(), 7, 3), 2);
        let mut left: Vec<_> = std::fs::read_dir(&nested)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [".b.mcap.8.tmp", "a.mcap"]);
    }
}
