//! Model persistence shared by every model class: drift-core's serde JSON, the firmware table image
//! (`drift_core::blob`), and files. Pure Rust; the classes in `tables.rs` only delegate.

use std::fs;
use std::path::Path;

use drift_core::blob::{self, Image};
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

/// Encodes a firmware table image.
pub fn to_image<M: Image>(tables: &M) -> Result<Vec<u8>, Error> {
    drift_evaluate::tables_folder::image_bytes(tables).map_err(Error::Image)
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

/// Writes a whole file atomically ([`drift_recording::write_atomic`]): a failed write never
/// leaves a half-written model behind.
pub fn write(path: &Path, contents: &[u8]) -> Result<(), Error> {
    drift_recording::write_atomic(path, contents).map_err(|source| Error::File {
        action: "write",
        path: path.to_owned(),
        source,
    })
}
