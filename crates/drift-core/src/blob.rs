//! The firmware table image: a compact, checksummed binary form of a model.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 4 | magic `GYDT` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`]) |
//! | 6 | 1 | model kind ([`Kind`]) |
//! | 7 | 1 | reserved, 0 |
//! | 8 | 4 | payload length `n`, bytes |
//! | 12 | n | the model, serialised by `postcard` (serde) |
//! | 12 + n | 4 | CRC-32/ISO-HDLC of bytes `0 .. 12 + n` |
//!
//! The payload codec is postcard's (well kept, no_std, no alloc); only the fixed header is ours.
//! Decoding checks, in order: length, magic, version, kind, declared length, CRC, payload, contents
//! (the model's own validation), so every byte string gets one specific error and never a panic.

use core::fmt;

use serde::{de::DeserializeOwned, Serialize};

use crate::error::Error;
use crate::model::Model;
use crate::polynomial::{PolynomialTables, RelativePolynomialTables};
use crate::recommended::RecommendedTables;
use crate::table::ModifiedTables;

mod in_place;
mod section;

pub use section::{
    decode_section, encode_section, section_len, SectionError, SECTION_MAGIC, SECTION_VERSION,
};

/// First four bytes of every image.
pub const MAGIC: [u8; 4] = *b"GYDT";
/// The image format version: the only one this build writes and reads. Any change to the
/// header or to the payload's shape (a model type's fields, in order) is a new version.
pub const FORMAT_VERSION: u16 = 1;
/// Bytes before the payload.
pub const HEADER_LEN: usize = 12;
/// Bytes after the payload (the CRC).
pub const TRAILER_LEN: usize = 4;

const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Which model an image holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// [`ModifiedTables`]: the paper's method.
    Modified = 1,
    /// [`PolynomialTables`]: a polynomial baseline.
    Polynomial = 2,
    /// [`RelativePolynomialTables`]: the polynomial baseline relative to the switch-on.
    RelativePolynomial = 3,
    /// [`RecommendedTables`]: the paper's drift correction with the turn-on bias fitted across
    /// every calibration activation.
    Recommended = 4,
}

/// A model that can be stored as a firmware image.
pub trait Image: Model + Serialize + DeserializeOwned {
    /// The kind byte written in the header.
    const KIND: Kind;

    /// Decodes `payload` (exactly one model) into `place` and validates it: what [`decode_into`]
    /// does after the header and CRC. The default decodes by value and assigns only a validated
    /// model (`place` unchanged on error), which suits small models; the paper's tables write in
    /// place instead.
    fn payload_into(payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        *place = from_payload(payload)?;
        Ok(())
    }
}

impl<const R: usize, const A: usize, const C: usize> Image for ModifiedTables<R, A, C> {
    const KIND: Kind = Kind::Modified;

    /// Field by field into `place`: the stack holds one curve at a time, never the tables. On
    /// error `place` is emptied (validation rejects it).
    fn payload_into(payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        let decoded = in_place::fill_modified(place, payload)
            .map_err(BlobError::Malformed)
            .and_then(|()| place.validate().map_err(BlobError::Invalid));
        if decoded.is_err() {
            in_place::empty(place);
        }
        decoded
    }
}

impl<const R: usize, const A: usize, const C: usize> Image for RecommendedTables<R, A, C> {
    const KIND: Kind = Kind::Recommended;

    /// In place, as the paper's tables it holds (the same stack bound). On error `place` is
    /// emptied (validation rejects it).
    fn payload_into(payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        let decoded = in_place::fill_exact(place, payload)
            .map_err(BlobError::Malformed)
            .and_then(|()| place.validate().map_err(BlobError::Invalid));
        if decoded.is_err() {
            for axis in &mut place.axes {
                in_place::empty_axis(&mut axis.table);
            }
        }
        decoded
    }
}

impl Image for PolynomialTables {
    const KIND: Kind = Kind::Polynomial;
}

impl Image for RelativePolynomialTables {
    const KIND: Kind = Kind::RelativePolynomial;
}

/// The model of a payload that holds exactly one, validated. Out of line: the model is built,
/// checked and validated in this one frame and written once into the caller's result, not copied
/// through `decode`'s frame (firmware decodes ~12-KB tables on a stack it must budget,
/// docs/embedded.md).
#[inline(never)]
fn from_payload<M: Image>(payload: &[u8]) -> Result<M, BlobError> {
    let (model, rest) = postcard::take_from_bytes::<M>(payload).map_err(BlobError::Malformed)?;
    if !rest.is_empty() {
        return Err(BlobError::Malformed(
            postcard::Error::DeserializeBadEncoding,
        ));
    }
    model.validate().map_err(BlobError::Invalid)?;
    Ok(model)
}

/// Why an image could not be encoded or decoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BlobError {
    /// The byte string ends before the image does.
    Truncated {
        /// Bytes the image needs.
        needed: usize,
        /// Bytes available.
        found: usize,
    },
    /// The first four bytes are not [`MAGIC`].
    BadMagic {
        /// The bytes found.
        found: [u8; 4],
    },
    /// The format version is not [`FORMAT_VERSION`].
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
    /// The image holds another kind of model than the one asked for (or an unknown kind).
    WrongKind {
        /// Kind asked for.
        expected: u8,
        /// Kind byte found.
        found: u8,
    },
    /// Bytes follow the image's CRC.
    TrailingBytes {
        /// How many.
        count: usize,
    },
    /// The stored CRC does not match the image's bytes.
    CrcMismatch {
        /// CRC stored in the image.
        stored: u32,
        /// CRC computed over the image.
        computed: u32,
    },
    /// The payload is not a valid encoding of the model, or holds more entries than this build's
    /// capacities.
    Malformed(postcard::Error),
    /// The payload decodes but its contents fail validation (the error names the field).
    Invalid(Error),
    /// Encoding: the output buffer is too small.
    BufferTooSmall,
}

impl fmt::Display for BlobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated { needed, found } => {
                write!(f, "table image truncated: needs {needed} bytes, got {found}")
            }
            Self::BadMagic { found } => write!(
                f,
                "not a gyrodrift table image: magic is {found:02x?}, expected {MAGIC:02x?} (\"GYDT\")"
            ),
            Self::UnsupportedVersion { found } => write!(
                f,
                "table image format version {found} is not supported (this build reads {FORMAT_VERSION})"
            ),
            Self::WrongKind { expected, found } => {
                write!(f, "table image holds model kind {found}, expected {expected}")
            }
            Self::TrailingBytes { count } => {
                write!(f, "{count} unexpected bytes after the table image's CRC")
            }
            Self::CrcMismatch { stored, computed } => write!(
                f,
                "table image CRC mismatch: stored {stored:#010x}, computed {computed:#010x} (corrupted)"
            ),
            Self::Malformed(error) => write!(f, "table image payload is malformed: {error}"),
            Self::Invalid(error) => write!(f, "table image contents are invalid: {error}"),
            Self::BufferTooSmall => f.write_str("output buffer too small for the table image"),
        }
    }
}

impl core::error::Error for BlobError {}

fn le_u16(bytes: &[u8], at: usize) -> u16 {
    let mut out = [0_u8; 2];
    if let Some(src) = bytes.get(at..at.saturating_add(2)) {
        out.copy_from_slice(src);
    }
    u16::from_le_bytes(out)
}

fn le_u32(bytes: &[u8], at: usize) -> u32 {
    let mut out = [0_u8; 4];
    if let Some(src) = bytes.get(at..at.saturating_add(4)) {
        out.copy_from_slice(src);
    }
    u32::from_le_bytes(out)
}

/// The length in bytes of `model`'s image, without writing it (to size a buffer exactly).
pub fn encoded_len<M: Image>(model: &M) -> Result<usize, BlobError> {
    let payload = postcard::serialize_with_flavor(model, postcard::ser_flavors::Size::default())
        .map_err(BlobError::Malformed)?;
    Ok(HEADER_LEN
        .saturating_add(payload)
        .saturating_add(TRAILER_LEN))
}

/// Encodes `model` into `buffer`; returns the image's length. The model is validated first, so an
/// image is never written from tables the firmware would reject.
pub fn encode<M: Image>(model: &M, buffer: &mut [u8]) -> Result<usize, BlobError> {
    model.validate().map_err(BlobError::Invalid)?;
    let payload_len = {
        let payload = buffer
            .get_mut(HEADER_LEN..)
            .ok_or(BlobError::BufferTooSmall)?;
        match postcard::to_slice(model, payload) {
            Ok(written) => written.len(),
            Err(postcard::Error::SerializeBufferFull) => return Err(BlobError::BufferTooSmall),
            Err(error) => return Err(BlobError::Malformed(error)),
        }
    };
    let body_len = HEADER_LEN.saturating_add(payload_len);
    let total = body_len.saturating_add(TRAILER_LEN);
    let declared = u32::try_from(payload_len).map_err(|_| BlobError::BufferTooSmall)?;
    let header = buffer
        .get_mut(..HEADER_LEN)
        .ok_or(BlobError::BufferTooSmall)?;
    header.copy_from_slice(&[0; HEADER_LEN]);
    for (dst, src) in header.iter_mut().zip(
        MAGIC
            .iter()
            .chain(&FORMAT_VERSION.to_le_bytes())
            .chain(&[M::KIND as u8, 0])
            .chain(&declared.to_le_bytes()),
    ) {
        *dst = *src;
    }
    let crc = CRC32.checksum(buffer.get(..body_len).ok_or(BlobError::BufferTooSmall)?);
    buffer
        .get_mut(body_len..total)
        .ok_or(BlobError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    Ok(total)
}

/// Decodes and validates an image of model type `M`, returned by value.
///
/// Building the paper's tables by value takes several times their size in stack (serde's nested
/// decoders): firmware decodes with [`decode_into`] instead, into a `static`.
pub fn decode<M: Image>(bytes: &[u8]) -> Result<M, BlobError> {
    from_payload(payload::<M>(bytes)?)
}

/// Decodes and validates an image of model type `M` into `place`, the firmware way: the paper's
/// tables ([`ModifiedTables`]) are written field by field where they live (a `static`), so
/// decoding needs well under 1 KB of stack whatever the tables' size (docs/embedded.md), and the
/// result is the same model [`decode`] returns.
///
/// On error `place` does not hold the image's model: it is unchanged when the header or CRC is
/// rejected; when the payload or its contents are, [`ModifiedTables`] are left empty (validation,
/// and so [`Corrector::new`](crate::Corrector::new), rejects them) and smaller models unchanged.
///
/// ```
/// use drift_core::blob::decode_into;
/// use drift_core::ModifiedTables;
/// # fn image() -> Vec<u8> {
/// #     let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/vectors.json")).unwrap();
/// #     let json: serde_json::Value = serde_json::from_str(&text).unwrap();
/// #     let hex = json["models"][0]["image_hex"].as_str().unwrap();
/// #     (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect()
/// # }
/// // Firmware keeps the tables in a `static` (e.g. cortex-m-rt's `static mut` in `#[entry]`,
/// // initialised with `ModifiedTables::EMPTY` at no stack cost).
/// let mut tables: ModifiedTables<8, 3, 16> = ModifiedTables::EMPTY;
/// decode_into(&image(), &mut tables)?;
/// assert!(drift_core::Corrector::new(&tables).is_ok());
/// # Ok::<(), drift_core::blob::BlobError>(())
/// ```
pub fn decode_into<M: Image>(bytes: &[u8], place: &mut M) -> Result<(), BlobError> {
    M::payload_into(payload::<M>(bytes)?, place)
}

/// The payload of an image of model type `M`, after checking the header, the length and the CRC.
fn payload<M: Image>(bytes: &[u8]) -> Result<&[u8], BlobError> {
    let minimum = HEADER_LEN.saturating_add(TRAILER_LEN);
    if bytes.len() < minimum {
        // Check the magic of whatever is there first: a short non-image is "not an image".
        if let Some(found) = bytes.get(..4) {
            if found != MAGIC {
                let mut magic = [0; 4];
                magic.copy_from_slice(found);
                return Err(BlobError::BadMagic { found: magic });
            }
        }
        return Err(BlobError::Truncated {
            needed: minimum,
            found: bytes.len(),
        });
    }
    let mut magic = [0; 4];
    if let Some(found) = bytes.get(..4) {
        magic.copy_from_slice(found);
    }
    if magic != MAGIC {
        return Err(BlobError::BadMagic { found: magic });
    }
    let version = le_u16(bytes, 4);
    if version != FORMAT_VERSION {
        return Err(BlobError::UnsupportedVersion { found: version });
    }
    let kind = bytes.get(6).copied().unwrap_or(0);
    if kind != M::KIND as u8 {
        return Err(BlobError::WrongKind {
            expected: M::KIND as u8,
            found: kind,
        });
    }
    let payload_len = le_u32(bytes, 8) as usize;
    let body_len = HEADER_LEN.saturating_add(payload_len);
    let total = body_len.saturating_add(TRAILER_LEN);
    if bytes.len() < total {
        return Err(BlobError::Truncated {
            needed: total,
            found: bytes.len(),
        });
    }
    if bytes.len() > total {
        return Err(BlobError::TrailingBytes {
            count: bytes.len().saturating_sub(total),
        });
    }
    let body = bytes.get(..body_len).unwrap_or_default();
    let stored = le_u32(bytes, body_len);
    let computed = CRC32.checksum(body);
    if stored != computed {
        return Err(BlobError::CrcMismatch { stored, computed });
    }
    Ok(body.get(HEADER_LEN..).unwrap_or_default())
}
