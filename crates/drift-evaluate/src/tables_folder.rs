//! A fit's tables folder, written and read in one place: `<folder>/<unit>/<model>.{json,bin}` for
//! the models of [`StoredModel`]. The JSON is drift-core's serde form (what people read and diff),
//! the `.bin` the checksummed firmware image (`drift_core::blob`).
//!
//! `gyrodrift fit`, `gyrodrift report`, `gyrodrift diagnose --extend` and Python's
//! `FittedUnit.save` all write through [`write()`], so their folders are the same bytes.

use std::path::{Path, PathBuf};

use drift_core::blob::{self, BlobError, Image, Provenance};
use drift_fit::FittedUnit;
use drift_recording::write_atomic_creating_folder;
use serde::Serialize;

/// Why a tables folder could not be written or read, naming the file. The message carries the
/// cause whole (it is not chained again as a `source`).
#[derive(Debug, thiserror::Error)]
pub enum TablesError {
    /// A model could not be encoded as a firmware image (invalid tables).
    #[error("{path}: cannot encode the firmware image: {problem}")]
    Encode {
        /// The image that was to be written.
        path: PathBuf,
        /// What the encoder refused.
        problem: BlobError,
    },
    /// σ(t) could not be encoded as a firmware section (invalid values).
    #[error("{path}: cannot encode the σ(t) section: {problem}")]
    Section {
        /// The section that was to be written.
        path: PathBuf,
        /// What the encoder refused.
        problem: blob::SectionError,
    },
    /// A model could not be written as JSON.
    #[error("{path}: cannot write the tables as JSON: {problem}")]
    Json {
        /// The file that was to be written.
        path: PathBuf,
        /// serde_json's error.
        problem: serde_json::Error,
    },
    /// Reading or writing a file failed.
    #[error("cannot {action} {path}: {problem}")]
    Io {
        /// "read" or "write".
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The I/O error.
        problem: std::io::Error,
    },
    /// A stored image is not a valid image of the expected model.
    #[error("{path}: {}", blob_message(problem))]
    Decode {
        /// The image.
        path: PathBuf,
        /// What the decoder refused.
        problem: BlobError,
    },
}

/// The model an image's kind byte stands for, by name (`modified.bin` and its kin hold these).
pub fn kind_name(kind: u8) -> String {
    use drift_core::blob::Kind;
    let named = [
        (
            Kind::Modified,
            "the paper's modified tables (modified.bin, by_history.bin)",
        ),
        (
            Kind::Polynomial,
            "a polynomial baseline (standard.bin, third_order.bin)",
        ),
        (
            Kind::RelativePolynomial,
            "the relative polynomial baseline (relative.bin)",
        ),
        (Kind::Recommended, "the recommended model (recommended.bin)"),
    ];
    named.iter().find(|(k, _)| *k as u8 == kind).map_or_else(
        || format!("an unknown model kind ({kind})"),
        |(_, name)| (*name).to_owned(),
    )
}

/// What a decoder refused, for people: a wrong model kind is named, not numbered.
pub fn blob_message(problem: &BlobError) -> String {
    match problem {
        BlobError::WrongKind { expected, found } => format!(
            "the image holds {}, where {} is expected",
            kind_name(*found),
            kind_name(*expected)
        ),
        other => other.to_string(),
    }
}

/// The models a tables folder holds for each unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoredModel {
    /// The paper's tables.
    Modified,
    /// The paper's curves with stage 3 keyed by heating history (firmware that keeps what it knew
    /// of the previous activation: `power_on_after`).
    ByHistory,
    /// The paper's standard polynomial.
    Standard,
    /// The 3rd-order polynomial.
    ThirdOrder,
    /// The least-squares polynomial relative to the switch-on.
    Relative,
    /// The recommended model: the paper's drift correction with the turn-on bias fitted on every
    /// calibration activation (firmware that keeps what it knew of the previous activation).
    Recommended,
}

impl StoredModel {
    /// Every stored model, in the order files are written.
    pub const ALL: [Self; 6] = [
        Self::Recommended,
        Self::Modified,
        Self::ByHistory,
        Self::Standard,
        Self::ThirdOrder,
        Self::Relative,
    ];

    /// The files' stem: `recommended`, `modified`, `by_history`, `standard`, `third_order`,
    /// `relative`.
    pub fn stem(self) -> &'static str {
        match self {
            Self::Modified => "modified",
            Self::ByHistory => "by_history",
            Self::Standard => "standard",
            Self::ThirdOrder => "third_order",
            Self::Relative => "relative",
            Self::Recommended => "recommended",
        }
    }

    /// The firmware image's path for `unit` in the tables folder `folder`.
    pub fn image_path(self, folder: &Path, unit: &str) -> PathBuf {
        folder.join(unit).join(format!("{}.bin", self.stem()))
    }
}

/// The firmware image of `model`, exactly as long as it needs to be, with no provenance.
pub fn image_bytes<M: Image>(model: &M) -> Result<Vec<u8>, BlobError> {
    image_bytes_for(model, &Provenance::default())
}

/// The firmware image of `model` whose header says where it comes from.
pub fn image_bytes_for<M: Image>(model: &M, provenance: &Provenance) -> Result<Vec<u8>, BlobError> {
    let mut image = vec![0; blob::encoded_len(model)?];
    let written = blob::encode_for(model, provenance, &mut image)?;
    image.truncate(written);
    Ok(image)
}

/// What this tool writes into the header of `unit_id`'s images: the unit, this version, and
/// today's date (UTC; `SOURCE_DATE_EPOCH`, seconds, when set, for reproducible builds).
pub fn provenance(unit_id: &str) -> Result<Provenance, BlobError> {
    Provenance::new(unit_id, env!("CARGO_PKG_VERSION"), today())
}

/// Today as `YYYYMMDD` (0 if the clock or `SOURCE_DATE_EPOCH` is unusable).
fn today() -> u32 {
    let now = match std::env::var("SOURCE_DATE_EPOCH") {
        Ok(seconds) => seconds
            .trim()
            .parse::<i64>()
            .ok()
            .and_then(|s| time::OffsetDateTime::from_unix_timestamp(s).ok()),
        Err(_) => Some(time::OffsetDateTime::now_utc()),
    };
    now.and_then(|date| {
        let year = u32::try_from(date.year()).ok()?;
        Some(year * 10_000 + u32::from(u8::from(date.month())) * 100 + u32::from(date.day()))
    })
    .unwrap_or(0)
}

/// drift-core's JSON of `model`, pretty-printed.
fn json_bytes<M: Serialize>(model: &M) -> Result<Vec<u8>, serde_json::Error> {
    serde_json::to_string_pretty(model).map(String::into_bytes)
}

/// A model's JSON and image files at `<dir>/<stem>.{json,bin}`, encoded in memory; the image's
/// header carries `provenance`.
pub fn model_files<M: Image>(
    dir: &Path,
    stem: &str,
    model: &M,
    provenance: &Provenance,
) -> Result<[(PathBuf, Vec<u8>); 2], TablesError> {
    let (json, bin) = (
        dir.join(format!("{stem}.json")),
        dir.join(format!("{stem}.bin")),
    );
    let json_text = json_bytes(model).map_err(|problem| TablesError::Json {
        path: json.clone(),
        problem,
    })?;
    let image = image_bytes_for(model, provenance).map_err(|problem| TablesError::Encode {
        path: bin.clone(),
        problem,
    })?;
    Ok([(json, json_text), (bin, image)])
}

/// Every file of `unit`'s folder under `folder`, encoded in memory.
pub fn unit_files(
    folder: &Path,
    unit: &FittedUnit,
) -> Result<Vec<(PathBuf, Vec<u8>)>, TablesError> {
    let dir = folder.join(&unit.unit_id);
    // Each image names its unit, so that `gyrodrift check` refuses it for another.
    let from = provenance(&unit.unit_id).map_err(|problem| TablesError::Encode {
        path: dir.clone(),
        problem,
    })?;
    let mut files = Vec::with_capacity(2 * StoredModel::ALL.len());
    for model in StoredModel::ALL {
        let stem = model.stem();
        let pair = match model {
            StoredModel::Modified => model_files(&dir, stem, &unit.modified, &from)?,
            StoredModel::ByHistory => model_files(&dir, stem, &unit.by_history, &from)?,
            StoredModel::Standard => model_files(&dir, stem, &unit.standard, &from)?,
            StoredModel::ThirdOrder => model_files(&dir, stem, &unit.third_order, &from)?,
            StoredModel::Relative => model_files(&dir, stem, &unit.relative, &from)?,
            StoredModel::Recommended => model_files(&dir, stem, &unit.recommended, &from)?,
        };
        files.extend(pair);
    }
    Ok(files)
}

/// Writes each unit's models as
/// `<folder>/<unit>/{recommended,modified,by_history,standard,third_order,relative}.{json,bin}`.
///
/// Every file is encoded in memory first, so an encoding error leaves the folder untouched; each
/// file is then replaced atomically, so none is ever half-written.
pub fn write(folder: &Path, fitted: &[FittedUnit]) -> Result<(), TablesError> {
    let mut files = Vec::new();
    for unit in fitted {
        files.extend(unit_files(folder, unit)?);
    }
    write_files(&files)
}

/// Writes each unit's σ(t) beside its tables: `<folder>/<unit>/uncertainty.json` (drift-core's
/// serde form) and `uncertainty.bin` (the firmware's σ(t) section, `drift_core::blob::encode_section`).
/// Encoded in memory first, then each file replaced atomically.
pub fn write_uncertainty(
    folder: &Path,
    units: &[crate::uncertainty::UnitUncertainty],
) -> Result<(), TablesError> {
    let mut files = Vec::new();
    for unit in units {
        let dir = folder.join(&unit.unit_id);
        let (json, bin) = (dir.join("uncertainty.json"), dir.join("uncertainty.bin"));
        let text = json_bytes(&unit.sigma).map_err(|problem| TablesError::Json {
            path: json.clone(),
            problem,
        })?;
        let section = section_bytes(&unit.sigma).map_err(|problem| TablesError::Section {
            path: bin.clone(),
            problem,
        })?;
        files.extend([(json, text), (bin, section)]);
    }
    write_files(&files)
}

/// The firmware σ(t) section of `uncertainty`, exactly as long as it needs to be.
pub fn section_bytes(uncertainty: &drift_core::Uncertainty) -> Result<Vec<u8>, blob::SectionError> {
    let mut bytes = vec![0; blob::section_len(uncertainty)?];
    let written = blob::encode_section(uncertainty, &mut bytes)?;
    bytes.truncate(written);
    Ok(bytes)
}

/// Writes files encoded in memory, each atomically, creating their folders.
pub fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<(), TablesError> {
    for (path, bytes) in files {
        write_atomic_creating_folder(path, bytes).map_err(|problem| TablesError::Io {
            action: "write",
            path: path.clone(),
            problem,
        })?;
    }
    Ok(())
}

/// Reads and decodes the firmware image at `path`.
pub fn read_image<M: Image>(path: &Path) -> Result<M, TablesError> {
    read_image_and_header(path).map(|(model, _)| model)
}

/// Reads and decodes the firmware image at `path`, with its header (which unit it calibrates).
pub fn read_image_and_header<M: Image>(path: &Path) -> Result<(M, blob::Header), TablesError> {
    let bytes = std::fs::read(path).map_err(|problem| TablesError::Io {
        action: "read",
        path: path.to_owned(),
        problem,
    })?;
    let decode = |bytes: &[u8]| Ok((blob::decode(bytes)?, blob::header(bytes)?));
    decode(&bytes).map_err(|problem| TablesError::Decode {
        path: path.to_owned(),
        problem,
    })
}
