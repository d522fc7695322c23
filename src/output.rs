//! Result files, written whole or not at all.

use std::path::Path;

use anyhow::Context;

/// Writes `bytes` to `path` atomically ([`drift_recording::write_atomic`]); the error names the
/// file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    drift_recording::write_atomic(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}
