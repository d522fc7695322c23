//! The σ(t) section: [`Uncertainty`] in firmware form, a small checksummed block of its own that
//! firmware stores beside a table image (its own file, or right after the image in flash).
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 4 | magic `GYSG` |
//! | 4 | 2 | section version ([`SECTION_VERSION`]) |
//! | 6 | 2 | reserved, 0 |
//! | 8 | 4 | payload length `n`, bytes |
//! | 12 | n | [`Uncertainty`], serialised by `postcard` |
//! | 12 + n | 4 | CRC-32/ISO-HDLC of bytes `0 .. 12 + n` |
//!
//! It does not depend on the table image's header: a section reads the same whatever image sits
//! before it, and an image reader that does not know sections never sees one.

use core::fmt;

use crate::uncertainty::Uncertainty;

/// First four bytes of every σ(t) section.
pub const SECTION_MAGIC: [u8; 4] = *b"GYSG";
/// The section's version: any change to [`Uncertainty`]'s fields is a new one. Version 1 (without
/// the residual heat's widening) is still read, as σ(t) with no widening beyond any heat.
pub const SECTION_VERSION: u16 = 2;
/// The first version, without `most_residual_heat_celsius` and `per_residual_celsius_beyond_dps`.
const VERSION_1: u16 = 1;

/// [`Uncertainty`] as version 1 stored it.
#[derive(serde::Deserialize)]
struct UncertaintyV1 {
    knots_ms: [u32; crate::SIGMA_KNOTS],
    sigma_dps: [[f32; crate::SIGMA_KNOTS]; crate::ACTIVATION_CLASSES],
    warm_above_celsius: f32,
    ambient_min_celsius: f32,
    ambient_max_celsius: f32,
    per_celsius_outside_dps: f32,
}

impl From<UncertaintyV1> for Uncertainty {
    fn from(v1: UncertaintyV1) -> Self {
        Self {
            knots_ms: v1.knots_ms,
            sigma_dps: v1.sigma_dps,
            warm_above_celsius: v1.warm_above_celsius,
            ambient_min_celsius: v1.ambient_min_celsius,
            ambient_max_celsius: v1.ambient_max_celsius,
            per_celsius_outside_dps: v1.per_celsius_outside_dps,
            most_residual_heat_celsius: [0.0; crate::AXES],
            per_residual_celsius_beyond_dps: 0.0,
        }
    }
}
const HEAD: usize = 12;
const TAIL: usize = 4;

const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Why bytes are not a valid σ(t) section.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SectionError {
    /// Fewer bytes than the header, payload and CRC need.
    Truncated {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        found: usize,
    },
    /// The first four bytes are not [`SECTION_MAGIC`].
    BadMagic {
        /// The bytes found.
        found: [u8; 4],
    },
    /// A version this build does not read.
    UnsupportedVersion {
        /// The version found.
        found: u16,
    },
    /// Bytes after the CRC (a section is read exactly).
    TrailingBytes {
        /// How many.
        count: usize,
    },
    /// The stored CRC does not match the bytes.
    CrcMismatch {
        /// CRC stored in the section.
        stored: u32,
        /// CRC computed over the bytes.
        computed: u32,
    },
    /// The payload is not an [`Uncertainty`].
    Malformed(postcard::Error),
    /// The values are out of range (the error names the field).
    Invalid(crate::error::Error),
    /// The output buffer is smaller than [`section_len`].
    BufferTooSmall,
}

impl fmt::Display for SectionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated { needed, found } => {
                write!(f, "σ(t) section truncated: needs {needed} bytes, got {found}")
            }
            Self::BadMagic { found } => write!(
                f,
                "not a gyrodrift σ(t) section: magic is {found:02x?}, expected {SECTION_MAGIC:02x?} (\"GYSG\")"
            ),
            Self::UnsupportedVersion { found } => write!(
                f,
                "σ(t) section version {found} is not supported (this build reads {VERSION_1} and {SECTION_VERSION})"
            ),
            Self::TrailingBytes { count } => {
                write!(f, "{count} unexpected bytes after the σ(t) section's CRC")
            }
            Self::CrcMismatch { stored, computed } => write!(
                f,
                "σ(t) section CRC mismatch: stored {stored:#010x}, computed {computed:#010x} (corrupted)"
            ),
            Self::Malformed(error) => write!(f, "σ(t) section payload is malformed: {error}"),
            Self::Invalid(error) => write!(f, "σ(t) section contents are invalid: {error}"),
            Self::BufferTooSmall => f.write_str("output buffer too small for the σ(t) section"),
        }
    }
}

impl core::error::Error for SectionError {}

fn le_u32(bytes: &[u8], at: usize) -> u32 {
    let mut out = [0_u8; 4];
    if let Some(src) = bytes.get(at..at.saturating_add(4)) {
        out.copy_from_slice(src);
    }
    u32::from_le_bytes(out)
}

/// Bytes [`encode_section`] writes for `uncertainty`.
pub fn section_len(uncertainty: &Uncertainty) -> Result<usize, SectionError> {
    let payload =
        postcard::serialize_with_flavor(uncertainty, postcard::ser_flavors::Size::default())
            .map_err(SectionError::Malformed)?;
    Ok(HEAD.saturating_add(payload).saturating_add(TAIL))
}

/// Writes `uncertainty` (validated first) as a section into `buffer`; returns the bytes written.
pub fn encode_section(uncertainty: &Uncertainty, buffer: &mut [u8]) -> Result<usize, SectionError> {
    uncertainty.validate().map_err(SectionError::Invalid)?;
    let payload_len = {
        let payload = buffer.get_mut(HEAD..).ok_or(SectionError::BufferTooSmall)?;
        match postcard::to_slice(uncertainty, payload) {
            Ok(written) => written.len(),
            Err(postcard::Error::SerializeBufferFull) => return Err(SectionError::BufferTooSmall),
            Err(error) => return Err(SectionError::Malformed(error)),
        }
    };
    let body = HEAD.saturating_add(payload_len);
    let declared = u32::try_from(payload_len).map_err(|_| SectionError::BufferTooSmall)?;
    let header = buffer.get_mut(..HEAD).ok_or(SectionError::BufferTooSmall)?;
    for (dst, src) in header.iter_mut().zip(
        SECTION_MAGIC
            .iter()
            .chain(&SECTION_VERSION.to_le_bytes())
            .chain(&[0, 0])
            .chain(&declared.to_le_bytes()),
    ) {
        *dst = *src;
    }
    let crc = CRC32.checksum(buffer.get(..body).ok_or(SectionError::BufferTooSmall)?);
    buffer
        .get_mut(body..body.saturating_add(TAIL))
        .ok_or(SectionError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    Ok(body.saturating_add(TAIL))
}

/// The validated [`Uncertainty`] of exactly one section. Checks, in order: length, magic,
/// version, declared length, CRC, payload, values.
pub fn decode_section(bytes: &[u8]) -> Result<Uncertainty, SectionError> {
    let truncated = |needed| SectionError::Truncated {
        needed,
        found: bytes.len(),
    };
    let head = bytes
        .get(..HEAD.saturating_add(TAIL))
        .ok_or(truncated(HEAD + TAIL))?;
    let mut magic = [0; 4];
    magic.copy_from_slice(head.get(..4).ok_or(truncated(HEAD + TAIL))?);
    if magic != SECTION_MAGIC {
        return Err(SectionError::BadMagic { found: magic });
    }
    let version = u16::from_le_bytes([
        head.get(4).copied().unwrap_or(0),
        head.get(5).copied().unwrap_or(0),
    ]);
    if version != SECTION_VERSION && version != VERSION_1 {
        return Err(SectionError::UnsupportedVersion { found: version });
    }
    let declared = usize::try_from(le_u32(bytes, 8)).unwrap_or(usize::MAX);
    let body = HEAD.saturating_add(declared);
    let total = body.saturating_add(TAIL);
    if bytes.len() < total {
        return Err(truncated(total));
    }
    if bytes.len() > total {
        return Err(SectionError::TrailingBytes {
            count: bytes.len().saturating_sub(total),
        });
    }
    let stored = le_u32(bytes, body);
    let computed = CRC32.checksum(bytes.get(..body).ok_or(truncated(total))?);
    if stored != computed {
        return Err(SectionError::CrcMismatch { stored, computed });
    }
    let payload = bytes.get(HEAD..body).ok_or(truncated(total))?;
    let (uncertainty, rest) = if version == VERSION_1 {
        postcard::take_from_bytes::<UncertaintyV1>(payload)
            .map(|(v1, rest)| (Uncertainty::from(v1), rest))
            .map_err(SectionError::Malformed)?
    } else {
        postcard::take_from_bytes::<Uncertainty>(payload).map_err(SectionError::Malformed)?
    };
    if !rest.is_empty() {
        return Err(SectionError::Malformed(
            postcard::Error::DeserializeBadEncoding,
        ));
    }
    uncertainty.validate().map_err(SectionError::Invalid)?;
    Ok(uncertainty)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> Uncertainty {
        Uncertainty {
            knots_ms: [0, 2_000, 5_000, 10_000, 20_000, 40_000, 80_000, 160_000],
            sigma_dps: [[0.002; 8], [0.004; 8]],
            warm_above_celsius: 0.5,
            ambient_min_celsius: 30.0,
            ambient_max_celsius: 40.0,
            per_celsius_outside_dps: 0.0005,
            most_residual_heat_celsius: [2.5, 2.6, 2.4],
            per_residual_celsius_beyond_dps: 0.0012,
        }
    }

    /// A version-1 section as the previous release wrote it (testdata/sigma-vectors.json then).
    const V1_HEX: &str = "47595347010000006300000000d00f8827904ea09c01c0b80280f10480e2097923733b3e05403b8f360e3b9cdcef3a31ebc53ada03ad3ac6f99b3a3e3f8c3a2bdec83ba94d9c3bc32a5e3b890c2b3bc009053b1422e03ad66ebb3a3815a93a0000003f0000f041000020428ffcc13933641e72";

    #[test]
    fn a_version_1_section_reads_without_widening_beyond_any_heat() {
        let bytes: std::vec::Vec<u8> = (0..V1_HEX.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&V1_HEX[i..i + 2], 16).unwrap())
            .collect();
        assert_eq!(u16::from_le_bytes([bytes[4], bytes[5]]), 1);
        let u = decode_section(&bytes).unwrap();
        assert_eq!(u.most_residual_heat_celsius, [0.0; 3]);
        assert_eq!(u.per_residual_celsius_beyond_dps, 0.0);
        assert_eq!((u.ambient_min_celsius, u.ambient_max_celsius), (30.0, 40.0));
        assert_eq!(u.knots_ms[7], 160_000);
        let mut buffer = [0u8; 256];
        let n = encode_section(&u, &mut buffer).unwrap();
        assert_eq!(u16::from_le_bytes([buffer[4], buffer[5]]), SECTION_VERSION);
        assert_eq!(
            decode_section(&buffer[..n]).unwrap(),
            u,
            "rewritten as the current version"
        );
    }

    #[test]
    fn a_section_round_trips_and_every_damage_is_named() {
        let u = example();
        let mut buffer = [0u8; 256];
        let n = encode_section(&u, &mut buffer).unwrap();
        assert_eq!(n, section_len(&u).unwrap());
        let bytes = &buffer[..n];
        assert_eq!(decode_section(bytes).unwrap(), u);
        assert!(matches!(
            decode_section(&bytes[..n - 1]),
            Err(SectionError::Truncated { .. })
        ));
        assert!(matches!(
            decode_section(&buffer[..n + 1]),
            Err(SectionError::TrailingBytes { count: 1 })
        ));
        let mut flipped = bytes.to_vec();
        flipped[20] ^= 1;
        assert!(matches!(
            decode_section(&flipped),
            Err(SectionError::CrcMismatch { .. })
        ));
        let mut magic = bytes.to_vec();
        magic[0] = b'X';
        assert!(matches!(
            decode_section(&magic),
            Err(SectionError::BadMagic { .. })
        ));
        let mut version = bytes.to_vec();
        version[4] = 9;
        assert!(matches!(
            decode_section(&version),
            Err(SectionError::UnsupportedVersion { found: 9 })
        ));
        let mut invalid = u;
        invalid.sigma_dps[0][0] = -1.0;
        assert!(matches!(
            encode_section(&invalid, &mut buffer),
            Err(SectionError::Invalid(_))
        ));
        assert_eq!(
            encode_section(&u, &mut [0u8; 20]),
            Err(SectionError::BufferTooSmall)
        );
    }

    #[test]
    fn any_bytes_give_an_error_or_a_valid_section_never_a_panic() {
        let mut buffer = [0u8; 256];
        let n = encode_section(&example(), &mut buffer).unwrap();
        for cut in 0..n {
            let _ = decode_section(&buffer[..cut]);
        }
        for i in 0..n {
            let mut damaged = buffer[..n].to_vec();
            damaged[i] = damaged[i].wrapping_add(0x41);
            if let Ok(u) = decode_section(&damaged) {
                u.validate().unwrap();
            }
        }
    }
}
