//! Two inputs that must be different data (calibration and evaluation, a campaign and its noise
//! floor) compared by content, not by path: a copy of a folder, or its `recordings/` subfolder,
//! names other files holding the same recordings.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The first recording of `second` whose bytes are those of a recording of `first`, with that
/// recording. Only files of equal length are read and compared.
fn first_shared(
    first: &[PathBuf],
    second: &[PathBuf],
) -> anyhow::Result<Option<(PathBuf, PathBuf)>> {
    let mut by_length: BTreeMap<u64, Vec<&Path>> = BTreeMap::new();
    for path in first {
        let length = std::fs::metadata(path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
            .len();
        by_length.entry(length).or_default().push(path);
    }
    for path in second {
        let length = std::fs::metadata(path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?
            .len();
        let Some(candidates) = by_length.get(&length) else {
            continue;
        };
        let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        for candidate in candidates {
            let other = std::fs::read(candidate)
                .map_err(|e| anyhow::anyhow!("{}: {e}", candidate.display()))?;
            if other == bytes {
                return Ok(Some((candidate.to_path_buf(), path.clone())));
            }
        }
    }
    Ok(None)
}

/// Refuses when a recording of `second` (given by `second_flag`) is a recording of `first` (given
/// by `first_flag`), naming both files and what to do: `why` says what the two inputs must be.
pub fn refuse_shared(
    (first_flag, first): (&str, &[PathBuf]),
    (second_flag, second): (&str, &[PathBuf]),
    why: &str,
) -> anyhow::Result<()> {
    if let Some((a, b)) = first_shared(first, second)? {
        anyhow::bail!(
            "{} ({second_flag}) holds the same recording as {} ({first_flag}): {why}",
            b.display(),
            a.display()
        );
    }
    Ok(())
}
