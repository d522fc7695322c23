//! Errors of the recording reader and writer: every variant names the file; message-level
//! variants name the topic and the message's index within that topic.

use std::path::{Path, PathBuf};

/// A recording (or another MCAP file of the format) could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// MCAP writer error.
    #[error("{path}: MCAP: {source}")]
    Mcap {
        /// The (temporary) file being written.
        path: PathBuf,
        /// The mcap error.
        source: mcap::McapError,
    },
    /// A message was written to a topic that was never registered (a bug).
    #[error("topic {topic} was not registered")]
    UnknownTopic {
        /// The topic.
        topic: String,
    },
    /// The recording cannot be written as given (e.g. its times overflow the ns clock).
    #[error("{path}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file was already finished.
    #[error("{path}: already finished")]
    Finished {
        /// The file.
        path: PathBuf,
    },
}

impl WriteError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }
    pub(crate) fn mcap(path: &Path, source: mcap::McapError) -> Self {
        Self::Mcap {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// A recording could not be read or failed validation. Every variant names the file;
/// message-level variants name the topic and the message's index within that topic (0-based).
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// An MCAP file cut short: it starts as one and lacks the closing magic (an interrupted
    /// write or copy).
    #[error("{path}: truncated: the MCAP file ends at byte {length} without its closing magic (an interrupted write or copy); record or copy it again")]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Its length in bytes: where it stops.
        length: usize,
    },
    /// The MCAP container itself is broken.
    #[error("{path}: MCAP: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The mcap error.
        source: mcap::McapError,
    },
    /// The reading was stopped by its [`crate::Progress`] (Ctrl-C in Python).
    #[error("{path}: reading interrupted")]
    Interrupted {
        /// The file.
        path: PathBuf,
    },
    /// The file is a ground-truth sidecar; fitting and diagnosis code must not read it.
    #[error("{path}: is simulator ground truth ({why}); the recording reader refuses to read it")]
    GroundTruth {
        /// The file.
        path: PathBuf,
        /// How it was recognised.
        why: String,
    },
    /// The recording metadata is missing or malformed.
    #[error("{path}: metadata `{name}`: {reason}")]
    Metadata {
        /// The file.
        path: PathBuf,
        /// Metadata record name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A required topic is absent.
    #[error("{path}: missing topic {topic}")]
    MissingTopic {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A message could not be decoded or is inconsistent with its neighbours.
    #[error("{path}: topic {topic}, message #{index}: {reason}")]
    Message {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Index of the message within its topic (0-based).
        index: usize,
        /// What is wrong: expected vs found.
        reason: String,
    },
}
