//! The firmware table image: a compact, checksummed binary form of a model.
//!
//! Layout of version 3, the one this build writes (all integers little-endian; version 2's
//! header):
//!
//! | offset | size | content |
//! |---|---|---|
//! | 0 | 4 | magic `GYDT` |
//! | 4 | 2 | format version, 3 ([`FORMAT_VERSION`]) |
//! | 6 | 1 | model kind ([`Kind`]) |
//! | 7 | 1 | reserved, 0 |
//! | 8 | 4 | payload length `n`, bytes |
//! | 12 | 2 | reference times per axis the model needs (`R`; [`Capacities`]) |
//! | 14 | 2 | ambients per axis it needs (`A`) |
//! | 16 | 2 | curves per ambient it needs (`C`) |
//! | 18 | 2 | reserved, 0 |
//! | 20 | 4 | date written, `YYYYMMDD` as a number, 0 if not said ([`Provenance`]) |
//! | 24 | 16 | writing tool's version, UTF-8, zero-padded |
//! | 40 | 24 | unit ID, UTF-8, zero-padded (empty if not said) |
//! | 64 | n | the model, serialised by `postcard` (serde) |
//! | 64 + n | 4 | CRC-32/ISO-HDLC of bytes `0 .. 64 + n` |
//!
//! Versions 1 and 2 are still read. Version 2 is the same header; its payload's settings lack
//! their last field, `sample_rate_hz` (read as 0, not stated). Version 1 is the first 12 bytes of
//! that header, then version 2's payload at 12 and the CRC at `12 + n`. The header is ours; the payload codec is postcard's (well
//! kept, no_std, no alloc), so a change to a model's fields is a new version, and so is a change
//! to the header.
//!
//! Decoding checks, in order: magic (erased flash, `0xFF`, is named as such), version, header
//! length, kind, capacities (version 2), declared length, CRC, payload, contents (the model's own
//! validation), so every byte string gets one specific error and never a panic. [`image_len`]
//! reads the length from the header alone, so firmware can take an image out of a flash sector
//! padded with erased bytes.

use serde::{de::DeserializeOwned, Serialize};

use crate::model::Model;
use crate::polynomial::{PolynomialTables, RelativePolynomialTables};
use crate::recommended::RecommendedTables;
use crate::table::ModifiedTables;

mod error;
mod header;
mod in_place;
mod layout;
mod legacy;
mod section;

pub use section::{
    decode_section, encode_section, section_len, SectionError, SECTION_MAGIC, SECTION_VERSION,
};

pub use error::BlobError;
pub use header::{Capacities, Header, Provenance};
pub use layout::{
    header_len, FORMAT_VERSION, HEADER_LEN_V1, HEADER_LEN_V2, MAGIC, TOOL_VERSION_LEN, TRAILER_LEN,
    UNIT_ID_LEN, VERSION_1, VERSION_2, VERSION_3,
};

/// Bytes before the payload in the version this build writes.
pub const HEADER_LEN: usize = HEADER_LEN_V2;

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

    /// The entries of each table dimension this type holds (its const generics).
    const CAPACITIES: Capacities = Capacities::NONE;

    /// The entries of each table dimension this model uses, written into the header so that a
    /// decoder with smaller capacities names the one it lacks.
    fn needs(&self) -> Capacities {
        Capacities::NONE
    }

    /// Decodes a format-`version` `payload` (exactly one model) into `place` and validates it:
    /// what [`decode_into`] does after the header and CRC. The default decodes by value and
    /// assigns only a validated model (`place` unchanged on error), which suits small models; the
    /// paper's tables write in place instead.
    fn payload_into(version: u16, payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        *place = from_payload(version, payload)?;
        Ok(())
    }
}

impl<const R: usize, const A: usize, const C: usize> Image for ModifiedTables<R, A, C> {
    const KIND: Kind = Kind::Modified;
    const CAPACITIES: Capacities = Capacities::of(R, A, C);

    fn needs(&self) -> Capacities {
        needs_of(self.axes.iter())
    }

    /// Field by field into `place`: the stack holds one curve at a time, never the tables. On
    /// error `place` is emptied (validation rejects it).
    fn payload_into(version: u16, payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        let decoded = legacy::payload(version, payload)
            .and_then(|payload| in_place::fill_modified(place, payload))
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
    const CAPACITIES: Capacities = Capacities::of(R, A, C);

    fn needs(&self) -> Capacities {
        needs_of(self.axes.iter().map(|axis| &axis.table))
    }

    /// In place, as the paper's tables it holds (the same stack bound). On error `place` is
    /// emptied (validation rejects it).
    fn payload_into(version: u16, payload: &[u8], place: &mut Self) -> Result<(), BlobError> {
        let decoded = legacy::payload(version, payload)
            .and_then(|payload| in_place::fill_exact(place, payload))
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

/// The largest count of each dimension over `axes`.
fn needs_of<'a, const R: usize, const A: usize, const C: usize>(
    axes: impl Iterator<Item = &'a crate::table::AxisTable<R, A, C>>,
) -> Capacities {
    let mut needs = Capacities::NONE;
    for axis in axes {
        let mut curves = 0;
        for ambient in &axis.ambients {
            curves = curves
                .max(ambient.curves.len())
                .max(ambient.residual_heat_celsius.len())
                .max(ambient.warm_starts.len());
        }
        let at_least = Capacities::of(axis.reference_ms.len(), axis.ambients.len(), curves);
        needs.reference_times = needs.reference_times.max(at_least.reference_times);
        needs.ambients = needs.ambients.max(at_least.ambients);
        needs.curves = needs.curves.max(at_least.curves);
    }
    needs
}

/// The model of a payload that holds exactly one, validated. Out of line: the model is built,
/// checked and validated in this one frame and written once into the caller's result, not copied
/// through `decode`'s frame (firmware decodes ~12-KB tables on a stack it must budget,
/// docs/embedded.md).
#[inline(never)]
fn from_payload<M: Image>(version: u16, payload: &[u8]) -> Result<M, BlobError> {
    let mut deserializer = postcard::Deserializer::from_flavor(
        legacy::payload(version, payload).map_err(BlobError::Malformed)?,
    );
    let model = M::deserialize(&mut deserializer).map_err(BlobError::Malformed)?;
    if !deserializer
        .finalize()
        .map_err(BlobError::Malformed)?
        .is_empty()
    {
        return Err(BlobError::Malformed(
            postcard::Error::DeserializeBadEncoding,
        ));
    }
    model.validate().map_err(BlobError::Invalid)?;
    Ok(model)
}

/// The length in bytes of `model`'s image, without writing it (to size a buffer exactly).
pub fn encoded_len<M: Image>(model: &M) -> Result<usize, BlobError> {
    let payload = postcard::serialize_with_flavor(model, postcard::ser_flavors::Size::default())
        .map_err(BlobError::Malformed)?;
    Ok(HEADER_LEN
        .saturating_add(payload)
        .saturating_add(TRAILER_LEN))
}

/// Encodes `model` into `buffer` with no [`Provenance`] ([`encode_for`] says where it comes
/// from); returns the image's length.
pub fn encode<M: Image>(model: &M, buffer: &mut [u8]) -> Result<usize, BlobError> {
    encode_for(model, &Provenance::default(), buffer)
}

/// Encodes `model` into `buffer` as a [`FORMAT_VERSION`] image whose header carries the capacities it
/// needs and `provenance`; returns the image's length. The model is validated first, so an image
/// is never written from tables the firmware would reject.
pub fn encode_for<M: Image>(
    model: &M,
    provenance: &Provenance,
    buffer: &mut [u8],
) -> Result<usize, BlobError> {
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
    header::write(header, M::KIND as u8, declared, &model.needs(), provenance);
    let crc = CRC32.checksum(buffer.get(..body_len).ok_or(BlobError::BufferTooSmall)?);
    let trailer = buffer
        .get_mut(body_len..total)
        .ok_or(BlobError::BufferTooSmall)?;
    for (dst, src) in trailer.iter_mut().zip(crc.to_le_bytes()) {
        *dst = src;
    }
    Ok(total)
}

/// The header at the start of `bytes` (version 1, 2 or 3), without checking the payload or the CRC:
/// which unit an image calibrates and what it needs, before decoding it.
pub fn header(bytes: &[u8]) -> Result<Header, BlobError> {
    header::read(bytes)
}

/// The length of the image at the start of `bytes`, read from its header: firmware that keeps
/// the image in a flash sector (erased to `0xFF` past it) decodes `&sector[..len]`.
///
/// ```
/// # fn image() -> Vec<u8> {
/// #     let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/vectors.json")).unwrap();
/// #     let json: serde_json::Value = serde_json::from_str(&text).unwrap();
/// #     let hex = json["models"][0]["image_hex"].as_str().unwrap();
/// #     (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect()
/// # }
/// use drift_core::blob::{decode_into, image_len, BlobError};
/// use drift_core::ModifiedTables;
/// let mut sector = [0xff_u8; 16 * 1024];
/// let image = image();
/// sector[..image.len()].copy_from_slice(&image);
///
/// let mut tables: ModifiedTables<8, 3, 16> = ModifiedTables::EMPTY;
/// let len = image_len(&sector)?;
/// decode_into(sector.get(..len).ok_or(BlobError::Truncated { needed: len, found: sector.len() })?, &mut tables)?;
/// assert_eq!(image_len(&[0xff; 64]), Err(BlobError::Erased));
/// # Ok::<(), BlobError>(())
/// ```
pub fn image_len(bytes: &[u8]) -> Result<usize, BlobError> {
    header::read_fixed(bytes).map(|header| header.image_len())
}

/// Decodes and validates an image of model type `M`, returned by value.
///
/// Building the paper's tables by value takes several times their size in stack (serde's nested
/// decoders): firmware decodes with [`decode_into`] instead, into a `static`.
pub fn decode<M: Image>(bytes: &[u8]) -> Result<M, BlobError> {
    let (version, payload) = payload::<M>(bytes)?;
    from_payload(version, payload)
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
    let (version, payload) = payload::<M>(bytes)?;
    M::payload_into(version, payload, place)
}

/// The format version and payload of an image of model type `M`, after checking the header (its
/// capacities against `M`'s), the length and the CRC.
fn payload<M: Image>(bytes: &[u8]) -> Result<(u16, &[u8]), BlobError> {
    let header = match header::read_fixed(bytes) {
        // A header cut short is an image cut short: say how long the shortest image is.
        Err(BlobError::Truncated { .. }) if bytes.len() < HEADER_LEN_V1 + TRAILER_LEN => {
            return Err(BlobError::Truncated {
                needed: HEADER_LEN_V1.saturating_add(TRAILER_LEN),
                found: bytes.len(),
            })
        }
        other => other?,
    };
    if header.kind != M::KIND as u8 {
        return Err(BlobError::WrongKind {
            expected: M::KIND as u8,
            found: header.kind,
        });
    }
    if let Some(needs) = &header.needs {
        needs.fit_in(&M::CAPACITIES)?;
    }
    let body_len = header.len().saturating_add(header.payload_len as usize);
    let total = header.image_len();
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
    let stored = layout::le_u32(bytes, body_len);
    let computed = CRC32.checksum(body);
    if stored != computed {
        return Err(BlobError::CrcMismatch { stored, computed });
    }
    Ok((header.version, body.get(header.len()..).unwrap_or_default()))
}
