//! The one rule for simulating into a folder, shared by `gyrodrift simulate` and Python's
//! `gyrodrift.simulate`: an empty (or missing) folder is used; a folder holding a campaign is
//! replaced only when asked to (`force`); anything else is never deleted.

use std::path::{Path, PathBuf};

use drift_recording::{COMPLETION_MARKER, RECORDINGS_DIR, TRUTH_DIR};

/// What a simulation writes into its output folder, and so what `force` replaces.
pub const WRITTEN: [&str; 3] = [RECORDINGS_DIR, TRUTH_DIR, COMPLETION_MARKER];

/// Why a folder cannot take a simulation. `flag` is how the caller asks to replace
/// (`--force`, `force=True`).
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// The folder holds something and replacing was not asked for.
    #[error("{} is not empty ({}): simulating into it would mix two campaigns; pass {flag} to replace the campaign there, or choose a new folder", path.display(), entries.join(", "))]
    NotEmpty {
        /// The folder.
        path: PathBuf,
        /// Its entries, sorted.
        entries: Vec<String>,
        /// How to ask for replacing.
        flag: &'static str,
    },
    /// The folder holds files no simulation writes.
    #[error("{} holds files `simulate` does not write ({}): {flag} replaces only a campaign; choose a new folder", path.display(), names.join(", "))]
    Foreign {
        /// The folder.
        path: PathBuf,
        /// The foreign entries, sorted.
        names: Vec<String>,
        /// How replacing was asked for.
        flag: &'static str,
    },
    /// The folder or an earlier campaign's file could not be read or removed.
    #[error("{action} {}: {source}", path.display())]
    Io {
        /// `reading` or `removing`.
        action: &'static str,
        /// The path.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// Refuses an output folder holding anything, unless `force`: then removes what an earlier
/// simulation wrote there, and refuses anything else it holds (it is not ours to delete).
pub fn prepare(out: &Path, force: bool, flag: &'static str) -> Result<(), FolderError> {
    let entries: Vec<String> = match std::fs::read_dir(out) {
        Ok(entries) => entries
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(source) => {
            return Err(FolderError::Io {
                action: "reading",
                path: out.to_owned(),
                source,
            })
        }
    };
    if entries.is_empty() {
        return Ok(());
    }
    let mut entries = entries;
    entries.sort();
    if !force {
        return Err(FolderError::NotEmpty {
            path: out.to_owned(),
            entries,
            flag,
        });
    }
    let names: Vec<String> = entries
        .into_iter()
        .filter(|name| !WRITTEN.contains(&name.as_str()))
        .collect();
    if !names.is_empty() {
        return Err(FolderError::Foreign {
            path: out.to_owned(),
            names,
            flag,
        });
    }
    for name in WRITTEN {
        let path = out.join(name);
        let removed = if path.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        match removed {
            Err(source) if source.kind() != std::io::ErrorKind::NotFound => {
                return Err(FolderError::Io {
                    action: "removing",
                    path,
                    source,
                })
            }
            _ => {}
        }
    }
    Ok(())
}
