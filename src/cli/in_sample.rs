//! Which recordings the tables were fitted on, kept beside the tables by content (length and
//! CRC-32 of each calibration recording), so `check` can say when it runs on its own calibration
//! data: a pass there says how well the tables fit what they were fitted on, not that the
//! calibration still holds.

use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_evaluate::pipeline::{self, Options};
use drift_report::write_atomic;

/// The file in a tables folder listing the calibration recordings.
pub const FILE: &str = "calibration-data.json";

/// One recording, by content.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fingerprint {
    /// The file's name where it was read (for messages only).
    pub recording: String,
    /// Its length, bytes.
    pub bytes: u64,
    /// CRC-32 (ISO-HDLC) of its bytes.
    pub crc32: u32,
}

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

fn fingerprint(path: &Path) -> anyhow::Result<Fingerprint> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(Fingerprint {
        recording: path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        bytes: bytes.len() as u64,
        crc32: CRC.checksum(&bytes),
    })
}

/// Writes `<tables>/calibration-data.json`: the recordings of `files` holding calibration
/// activations under `options`.
pub fn write(tables: &Path, files: &[PathBuf], options: &Options) -> anyhow::Result<()> {
    let mut listed = Vec::new();
    for path in files {
        if pipeline::calibration_file(path, options)? == Some(true) {
            listed.push(fingerprint(path)?);
        }
    }
    write_atomic(
        &tables.join(FILE),
        serde_json::to_string_pretty(&listed)?.as_bytes(),
    )
}

/// The recordings of `files` whose content is a calibration recording of the tables in `tables`,
/// each with the calibration recording's name; empty when the folder does not list them.
pub fn shared(tables: &Path, files: &[PathBuf]) -> anyhow::Result<Vec<(PathBuf, String)>> {
    let path = tables.join(FILE);
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(Vec::new());
    };
    let listed: Vec<Fingerprint> =
        serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
    let mut found = Vec::new();
    for file in files {
        let length = std::fs::metadata(file)
            .with_context(|| format!("reading {}", file.display()))?
            .len();
        if !listed.iter().any(|f| f.bytes == length) {
            continue;
        }
        let mine = fingerprint(file)?;
        if let Some(f) = listed
            .iter()
            .find(|f| f.bytes == mine.bytes && f.crc32 == mine.crc32)
        {
            found.push((file.clone(), f.recording.clone()));
        }
    }
    Ok(found)
}
