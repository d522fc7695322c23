//! The image's fixed byte layout (the `blob` module's documentation draws it): constants and the
//! little-endian reads every other part of the format shares.

/// First four bytes of every image.
pub const MAGIC: [u8; 4] = *b"GYDT";
/// The first version: magic, version, kind, payload length (12 bytes).
pub const VERSION_1: u16 = 1;
/// Version 2 adds the capacities the model needs, the unit's ID, the tool's version and the date
/// (64 bytes).
pub const VERSION_2: u16 = 2;
/// Version 3 has version 2's header; its payload's settings end with `sample_rate_hz`
/// (versions 1 and 2 read as 0, not stated).
pub const VERSION_3: u16 = 3;
/// The image format version this build writes. It reads it, [`VERSION_2`] and [`VERSION_1`]. Any
/// change to the header or to the payload's shape (a model type's fields, in order) is a new
/// version.
pub const FORMAT_VERSION: u16 = VERSION_3;
/// Header length of a version-1 image.
pub const HEADER_LEN_V1: usize = 12;
/// Header length of a version-2 or -3 image.
pub const HEADER_LEN_V2: usize = 64;
/// Bytes after the payload (the CRC).
pub const TRAILER_LEN: usize = 4;
/// Bytes for the unit's ID in a version-2 header (UTF-8, zero-padded).
pub const UNIT_ID_LEN: usize = 24;
/// Bytes for the writing tool's version in a version-2 header (UTF-8, zero-padded).
pub const TOOL_VERSION_LEN: usize = 16;

pub(super) const KIND_AT: usize = 6;
pub(super) const PAYLOAD_LEN_AT: usize = 8;
pub(super) const CAPACITIES_AT: usize = 12;
pub(super) const DATE_AT: usize = 20;
pub(super) const TOOL_AT: usize = 24;
pub(super) const UNIT_AT: usize = 40;

/// Header length of `version` (0 for a version this build does not read).
pub fn header_len(version: u16) -> usize {
    match version {
        VERSION_1 => HEADER_LEN_V1,
        VERSION_2 | VERSION_3 => HEADER_LEN_V2,
        _ => 0,
    }
}

// Array reads through `first_chunk`, never `copy_from_slice`: its length check panics with a
// formatted message, which would link `core::fmt` into firmware built without LTO.
pub(super) fn array<const N: usize>(bytes: &[u8], at: usize) -> Option<[u8; N]> {
    bytes.get(at..)?.first_chunk::<N>().copied()
}

pub(super) fn le_u16(bytes: &[u8], at: usize) -> u16 {
    u16::from_le_bytes(array(bytes, at).unwrap_or_default())
}

pub(super) fn le_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(array(bytes, at).unwrap_or_default())
}
