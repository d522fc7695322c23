//! The firmware table image: a compact, checksummed binary form of a model.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 4 | magic `GYDT` |
//! | 4 | 2 | format version ([`FORMAT_VERSION`]; versions 1 to 5 still read) |
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
use crate::extension::{Extension, ExtraTerm, SwitchOnRate, Term, MAX_TERMS};
use crate::model::Model;
use crate::polynomial::PolynomialTables;
use crate::settings::Settings;
use crate::table::{AmbientCurves, AxisTable, Curve, ModifiedTables};
use crate::AXES;

/// First four bytes of every image.
pub const MAGIC: [u8; 4] = *b"GYDT";
/// The image format version this build writes. Version 2 added the extended model's extra terms
/// to [`ModifiedTables`]; version 3 gave the auxiliary-input term a low-pass time constant
/// ([`Term::Aux`]); version 4 lets stage 3 be keyed by heating history
/// ([`AmbientCurves::residual_heat_celsius`]); version 5 gives warm starts their own initial bias
/// ([`AmbientCurves::warm_starts`]); version 6 starts the temperature-rate filter at the rate
/// the unit has at switch-on ([`Extension::switch_on_rate`]). This build still reads version-1 images (they
/// load with no extra terms), version-2 images (their auxiliary terms load unfiltered, time
/// constant 0, as they were meant), version-3 images (stage 3 keyed by rise, as the paper's),
/// version-4 images (the paper's initial bias, a function of the switch-on temperature alone) and
/// version-5 images (the rate filter starts at rest, [`SwitchOnRate::AT_REST`]).
pub const FORMAT_VERSION: u16 = 6;
/// The oldest image format version this build reads.
pub const OLDEST_READABLE_VERSION: u16 = 1;
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
}

/// A model that can be stored as a firmware image.
pub trait Image: Model + Serialize + DeserializeOwned {
    /// The kind byte written in the header.
    const KIND: Kind;

    /// Decodes a payload written by format `version` (already checked to be readable) that holds
    /// exactly one model, and validates it. Models whose payload changed between versions
    /// override this to read the older form.
    fn from_payload(version: u16, payload: &[u8]) -> Result<Self, BlobError> {
        let _ = version;
        whole(postcard::take_from_bytes(payload))
    }
}

/// The model of a decoded payload, which must have held nothing else, validated. Inlined into
/// each decoder: the model is then built and validated in one frame and written once into the
/// caller's result, not copied through a frame per step (firmware decodes ~12-KB tables on a stack
/// it must budget, docs/embedded.md).
#[inline(always)]
fn whole<M: Model>(decoded: postcard::Result<(M, &[u8])>) -> Result<M, BlobError> {
    let (model, rest) = decoded.map_err(BlobError::Malformed)?;
    if !rest.is_empty() {
        return Err(BlobError::Malformed(
            postcard::Error::DeserializeBadEncoding,
        ));
    }
    model.validate().map_err(BlobError::Invalid)?;
    Ok(model)
}

/// A version-1 to -3 ambient: stage 3 keyed by rise only.
#[derive(serde::Deserialize)]
struct AmbientCurvesV3<const R: usize, const C: usize> {
    ambient_celsius: f32,
    initial_bias_dps: f32,
    curves: heapless::Vec<Curve<R>, C>,
}

/// A version-1 to -3 axis table.
#[derive(serde::Deserialize)]
struct AxisTableV3<const R: usize, const A: usize, const C: usize> {
    reference_ms: heapless::Vec<u32, R>,
    ambients: heapless::Vec<AmbientCurvesV3<R, C>, A>,
}

impl<const R: usize, const A: usize, const C: usize> From<AxisTableV3<R, A, C>>
    for AxisTable<R, A, C>
{
    fn from(v3: AxisTableV3<R, A, C>) -> Self {
        let mut ambients = heapless::Vec::new();
        for ambient in v3.ambients {
            // The same capacity on both sides: never full.
            let _ = ambients.push(AmbientCurves {
                ambient_celsius: ambient.ambient_celsius,
                initial_bias_dps: ambient.initial_bias_dps,
                curves: ambient.curves,
                residual_heat_celsius: heapless::Vec::new(),
                warm_starts: heapless::Vec::new(),
            });
        }
        Self {
            reference_ms: v3.reference_ms,
            ambients,
        }
    }
}

/// A version-4 ambient: no warm starts.
#[derive(serde::Deserialize)]
struct AmbientCurvesV4<const R: usize, const C: usize> {
    ambient_celsius: f32,
    initial_bias_dps: f32,
    curves: heapless::Vec<Curve<R>, C>,
    residual_heat_celsius: heapless::Vec<f32, C>,
}

/// A version-4 axis table.
#[derive(serde::Deserialize)]
struct AxisTableV4<const R: usize, const A: usize, const C: usize> {
    reference_ms: heapless::Vec<u32, R>,
    ambients: heapless::Vec<AmbientCurvesV4<R, C>, A>,
}

impl<const R: usize, const A: usize, const C: usize> From<AxisTableV4<R, A, C>>
    for AxisTable<R, A, C>
{
    fn from(v4: AxisTableV4<R, A, C>) -> Self {
        let mut ambients = heapless::Vec::new();
        for ambient in v4.ambients {
            // The same capacity on both sides: never full.
            let _ = ambients.push(AmbientCurves {
                ambient_celsius: ambient.ambient_celsius,
                initial_bias_dps: ambient.initial_bias_dps,
                curves: ambient.curves,
                residual_heat_celsius: ambient.residual_heat_celsius,
                warm_starts: heapless::Vec::new(),
            });
        }
        Self {
            reference_ms: v4.reference_ms,
            ambients,
        }
    }
}

/// The extension of versions 3 to 5: the rate filter started at rest.
#[derive(serde::Deserialize)]
struct ExtensionV5 {
    terms: heapless::Vec<ExtraTerm, MAX_TERMS>,
}

impl From<ExtensionV5> for Extension {
    fn from(v5: ExtensionV5) -> Self {
        Self {
            terms: v5.terms,
            switch_on_rate: [SwitchOnRate::AT_REST; AXES],
        }
    }
}

/// A version-5 modified-model payload.
#[derive(serde::Deserialize)]
struct ModifiedTablesV5<const R: usize, const A: usize, const C: usize> {
    settings: Settings,
    axes: [AxisTable<R, A, C>; AXES],
    extension: ExtensionV5,
}

/// A version-4 modified-model payload.
#[derive(serde::Deserialize)]
struct ModifiedTablesV4<const R: usize, const A: usize, const C: usize> {
    settings: Settings,
    axes: [AxisTableV4<R, A, C>; AXES],
    extension: ExtensionV5,
}

/// A version-1 modified-model payload: the tables before the extended model existed.
#[derive(serde::Deserialize)]
struct ModifiedTablesV1<const R: usize, const A: usize, const C: usize> {
    settings: Settings,
    axes: [AxisTableV3<R, A, C>; AXES],
}

/// A version-3 modified-model payload.
#[derive(serde::Deserialize)]
struct ModifiedTablesV3<const R: usize, const A: usize, const C: usize> {
    settings: Settings,
    axes: [AxisTableV3<R, A, C>; AXES],
    extension: ExtensionV5,
}

/// A version-2 extra term: the auxiliary input had no time constant.
#[derive(serde::Deserialize)]
enum TermV2 {
    TemperatureRate { time_constant_ms: u32 },
    Aux { input: u8 },
    AxisRise { axis: u8 },
    RiseSquared,
}

/// A version-2 [`ExtraTerm`].
#[derive(serde::Deserialize)]
struct ExtraTermV2 {
    term: TermV2,
    centre: [f32; AXES],
    coefficient: [f32; AXES],
}

/// A version-2 modified-model payload.
#[derive(serde::Deserialize)]
struct ModifiedTablesV2<const R: usize, const A: usize, const C: usize> {
    settings: Settings,
    axes: [AxisTableV3<R, A, C>; AXES],
    /// The extension, a one-field struct, which postcard writes as its field.
    terms: heapless::Vec<ExtraTermV2, MAX_TERMS>,
}

impl From<ExtraTermV2> for ExtraTerm {
    fn from(v2: ExtraTermV2) -> Self {
        let term = match v2.term {
            TermV2::TemperatureRate { time_constant_ms } => {
                Term::TemperatureRate { time_constant_ms }
            }
            TermV2::Aux { input } => Term::Aux {
                input,
                time_constant_ms: 0,
            },
            TermV2::AxisRise { axis } => Term::AxisRise { axis },
            TermV2::RiseSquared => Term::RiseSquared,
        };
        Self {
            term,
            centre: v2.centre,
            coefficient: v2.coefficient,
        }
    }
}

impl<const R: usize, const A: usize, const C: usize> Image for ModifiedTables<R, A, C> {
    const KIND: Kind = Kind::Modified;

    fn from_payload(version: u16, payload: &[u8]) -> Result<Self, BlobError> {
        // One function per version, never inlined: each needs stack for its own copy of the
        // tables, and in one frame they would add up.
        match version {
            1 => from_v1(payload),
            2 => from_v2(payload),
            3 => from_v3(payload),
            4 => from_v4(payload),
            5 => from_v5(payload),
            _ => from_current(payload),
        }
    }
}

#[inline(never)]
fn from_v1<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    let (v1, rest) = postcard::take_from_bytes::<ModifiedTablesV1<R, A, C>>(payload)
        .map_err(BlobError::Malformed)?;
    let tables = ModifiedTables {
        settings: v1.settings,
        axes: v1.axes.map(AxisTable::from),
        extension: Extension::NONE,
    };
    whole(Ok((tables, rest)))
}

#[inline(never)]
fn from_v3<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    let (v3, rest) = postcard::take_from_bytes::<ModifiedTablesV3<R, A, C>>(payload)
        .map_err(BlobError::Malformed)?;
    let tables = ModifiedTables {
        settings: v3.settings,
        axes: v3.axes.map(AxisTable::from),
        extension: v3.extension.into(),
    };
    whole(Ok((tables, rest)))
}

#[inline(never)]
fn from_v4<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    let (v4, rest) = postcard::take_from_bytes::<ModifiedTablesV4<R, A, C>>(payload)
        .map_err(BlobError::Malformed)?;
    let tables = ModifiedTables {
        settings: v4.settings,
        axes: v4.axes.map(AxisTable::from),
        extension: v4.extension.into(),
    };
    whole(Ok((tables, rest)))
}

#[inline(never)]
fn from_v5<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    let (v5, rest) = postcard::take_from_bytes::<ModifiedTablesV5<R, A, C>>(payload)
        .map_err(BlobError::Malformed)?;
    let tables = ModifiedTables {
        settings: v5.settings,
        axes: v5.axes,
        extension: v5.extension.into(),
    };
    whole(Ok((tables, rest)))
}

#[inline(never)]
fn from_v2<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    let (v2, rest) = postcard::take_from_bytes::<ModifiedTablesV2<R, A, C>>(payload)
        .map_err(BlobError::Malformed)?;
    let mut extension = Extension::NONE;
    for term in v2.terms {
        // The same capacity on both sides: never full.
        let _ = extension.terms.push(term.into());
    }
    let tables = ModifiedTables {
        settings: v2.settings,
        axes: v2.axes.map(AxisTable::from),
        extension,
    };
    whole(Ok((tables, rest)))
}

#[inline(never)]
fn from_current<const R: usize, const A: usize, const C: usize>(
    payload: &[u8],
) -> Result<ModifiedTables<R, A, C>, BlobError> {
    whole(postcard::take_from_bytes(payload))
}

impl Image for PolynomialTables {
    const KIND: Kind = Kind::Polynomial;
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
    /// The format version is outside [`OLDEST_READABLE_VERSION`] ..= [`FORMAT_VERSION`].
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
                "table image format version {found} is not supported (this build reads {OLDEST_READABLE_VERSION} to {FORMAT_VERSION})"
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

/// Decodes and validates an image of model type `M`.
///
/// The decoded model is returned by value; for large tables on a small stack, decode once at
/// start-up into a `static` (see `docs/embedded.md` for the stack this takes).
pub fn decode<M: Image>(bytes: &[u8]) -> Result<M, BlobError> {
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
    if !(OLDEST_READABLE_VERSION..=FORMAT_VERSION).contains(&version) {
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
    let payload = body.get(HEADER_LEN..).unwrap_or_default();
    M::from_payload(version, payload)
}
