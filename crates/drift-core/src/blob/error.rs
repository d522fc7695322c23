//! Why an image could not be encoded or decoded: one error per check, in the decoder's order.

use core::fmt;

use super::layout::{MAGIC, VERSION_1, VERSION_2};
use crate::error::Error;

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
    /// The first four bytes are `0xFF`: erased flash, no image was written there.
    Erased,
    /// The format version is not one this build reads ([`VERSION_1`], [`VERSION_2`], [`VERSION_3`](super::VERSION_3)).
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
    /// The header says the model needs more entries of a table dimension than the type decoded
    /// into holds (its const generic): firmware built with too small tables.
    Capacity {
        /// Which dimension, with its const generic: "reference times (R)", "ambients (A)",
        /// "curves per ambient (C)".
        what: &'static str,
        /// Entries the image's model needs.
        needed: u16,
        /// Entries the type holds.
        capacity: u16,
    },
    /// A header field is not what its layout allows (e.g. an ID that is not UTF-8).
    BadHeader {
        /// The field.
        field: &'static str,
    },
    /// Encoding: a header field's text is longer than its place in the header.
    TooLong {
        /// The field.
        field: &'static str,
        /// Its length, bytes (UTF-8).
        len: usize,
        /// The most the header holds.
        max: usize,
    },
    /// The payload is not a valid encoding of the model, or (a version-1 image, whose header does
    /// not say what it needs) holds more entries than this build's capacities.
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
            Self::Erased => f.write_str(
                "no table image: the bytes read 0xFF, erased flash (was the image written?)",
            ),
            Self::UnsupportedVersion { found } => write!(
                f,
                "table image format version {found} is not supported (this build reads {VERSION_1} and {VERSION_2})"
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
            Self::Capacity {
                what,
                needed,
                capacity,
            } => write!(
                f,
                "table image needs {needed} {what}, this build's tables hold {capacity}: build the firmware's tables with at least {needed}"
            ),
            Self::BadHeader { field } => {
                write!(f, "table image header: the {field} is not valid UTF-8")
            }
            Self::TooLong { field, len, max } => write!(
                f,
                "the {field} is {len} bytes long, the table image's header holds at most {max}"
            ),
            Self::Malformed(error) => write!(f, "table image payload is malformed: {error}"),
            Self::Invalid(error) => write!(f, "table image contents are invalid: {error}"),
            Self::BufferTooSmall => f.write_str("output buffer too small for the table image"),
        }
    }
}

impl core::error::Error for BlobError {}
