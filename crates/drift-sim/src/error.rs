//! Errors of the simulator. Reading and writing recordings has its own errors in
//! `drift_recording`.

use std::path::{Path, PathBuf};

/// Something went wrong while simulating or writing.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The campaign description is invalid.
    #[error("invalid campaign: {field}: {reason}")]
    Campaign {
        /// Which field (e.g. `protocol.intervals_min[2]`).
        field: String,
        /// What was expected and what was found.
        reason: String,
    },
    /// The campaign file could not be parsed.
    #[error("{path}: cannot parse campaign: {reason}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Parser message (with line/column when the parser gives one).
        reason: String,
    },
    /// A unit's physical parameters are invalid (e.g. a non-positive heat capacity).
    #[error("unit {unit}: {reason}")]
    Physics {
        /// Unit id.
        unit: String,
        /// Reason.
        reason: String,
    },
    /// The run was stopped by its progress hook (Ctrl-C in Python); its files are unfinished.
    #[error("simulation interrupted")]
    Interrupted,
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Writing a recording or sidecar failed.
    #[error(transparent)]
    Write(#[from] drift_recording::WriteError),
    /// JSON serialisation of a sidecar failed.
    #[error("{path}: JSON: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The error.
        source: serde_json::Error,
    },
}

impl SimError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }
    pub(crate) fn campaign(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Campaign {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
