//! Model persistence shared by every model class: drift-core's serde JSON, the firmware table image
//! (`drift_core::blob`), and files. Pure Rust; the classes in `tables.rs` only delegate.

use std::fs;
use std::io::Write;
use std::path::Path;

use drift_core::blob::{self, BlobError, Image};
use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::errors::Error;

/// Parses drift-core's JSON for model `M` (called `model` in errors) and validates it.
pub fn from_json<M: Image + DeserializeOwned>(model: &'static str, text: &str) -> Result<M, Error> {
    let tables: M = serde_json::from_str(text).map_err(|source| Error::Json { model, source })?;
    tables.validate().map_err(Error::Table)?;
    Ok(tables)
}

/// drift-core's JSON for `tables`, pretty-printed (what people read and diff).
pub fn to_json<M: Serialize>(model: &'static str, tables: &M) -> Result<String, Error> {
    serde_json::to_string_pretty(tables).map_err(|source| Error::Json { model, source })
}

/// Decodes (and validates) a firmware table image.
pub fn from_image<M: Image>(bytes: &[u8]) -> Result<M, Error> {
    blob::decode(bytes).map_err(Error::Image)
}

/// Encodes a firmware table image, growing the buffer until the image fits.
pub fn to_image<M: Image>(tables: &M) -> Result<Vec<u8>, Error> {
    // The largest host model (16 × 12 × 32 capacities) takes about 150 KB; stop well beyond.
    const LIMIT: usize = 16 << 20;
    let mut buffer = vec![0_u8; 4096];
    loop {
        match blob::encode(tables, &mut buffer) {
            Ok(length) => {
                buffer.truncate(length);
                return Ok(buffer);
            }
            Err(BlobError::BufferTooSmall) if buffer.len() < LIMIT => {
                buffer.resize(buffer.len().saturating_mul(2), 0);
            }
            Err(error) => return Err(Error::Image(error)),
        }
    }
}

/// Reads a whole file.
pub fn read(path: &Path) -> Result<Vec<u8>, Error> {
    fs::read(path).map_err(|source| Error::File {
        action: "read",
        path: path.to_owned(),
        source,
    })
}

/// Reads a whole UTF-8 text file.
pub fn read_text(path: &Path) -> Result<String, Error> {
    fs::read_to_string(path).map_err(|source| Error::File {
        action: "read",
        path: path.to_owned(),
        source,
    })
}

/// Writes a whole file atomically: a temporary file next to it, then a rename, so a failed write
/// never leaves a half-written model behind.
pub fn write(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let error = |source| Error::File {
        action: "write",
        path: path.to_owned(),
        source,
    };
    let mut temporary = path.as_os_str().to_owned();
    temporary.push(format!(".tmp-{}", std::process::id()));
    let temporary = Path::new(&temporary);
    let result = fs::File::create(temporary)
        .and_then(|mut file| {
            file.write_all(contents)?;
            file.sync_all()
        })
        .and_then(|()| fs::rename(temporary, path));
    if result.is_err() {
        // Best effort: the temporary may not even exist (e.g. the folder is missing).
        let _ = fs::remove_file(temporary);
    }
    result.map_err(error)
}
