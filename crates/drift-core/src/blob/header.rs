//! The image's fixed header, every version (2 and 3 share one layout): what it says (kind, payload
//! length and, from version 2, the capacities the model needs and where the image comes from),
//! read without the payload, and written. Layouts: the `blob` module's documentation.

use heapless::String;

use super::error::BlobError;
use super::layout::{
    array, header_len, le_u16, le_u32, CAPACITIES_AT, DATE_AT, FORMAT_VERSION, HEADER_LEN_V1,
    KIND_AT, MAGIC, PAYLOAD_LEN_AT, TOOL_AT, TOOL_VERSION_LEN, TRAILER_LEN, UNIT_AT, UNIT_ID_LEN,
    VERSION_2,
};

/// How many entries of each table dimension a model holds: what a firmware's capacities (the
/// tables' const generics `R`, `A`, `C`) must be at least to decode it. 0 where the kind has no
/// such dimension (the polynomial baselines' sizes are fixed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Capacities {
    /// Reference times per axis (`R`).
    pub reference_times: u16,
    /// Calibration ambients per axis (`A`).
    pub ambients: u16,
    /// Curves (and residual heats, warm starts) per ambient (`C`).
    pub curves: u16,
}

impl Capacities {
    /// No table dimensions.
    pub const NONE: Self = Self {
        reference_times: 0,
        ambients: 0,
        curves: 0,
    };

    /// The first dimension where `self` (what a model needs) exceeds `available` (what a build
    /// offers), as an error naming it.
    pub fn fit_in(&self, available: &Self) -> Result<(), BlobError> {
        for (what, needed, capacity) in [
            (
                "reference times (R)",
                self.reference_times,
                available.reference_times,
            ),
            ("ambients (A)", self.ambients, available.ambients),
            ("curves per ambient (C)", self.curves, available.curves),
        ] {
            if needed > capacity {
                return Err(BlobError::Capacity {
                    what,
                    needed,
                    capacity,
                });
            }
        }
        Ok(())
    }

    /// Capacities of a build's const generics (or a model's counts), saturated at `u16::MAX`.
    pub const fn of(reference_times: usize, ambients: usize, curves: usize) -> Self {
        Self {
            reference_times: narrow(reference_times),
            ambients: narrow(ambients),
            curves: narrow(curves),
        }
    }
}

#[allow(clippy::cast_possible_truncation)] // checked: `n` fits
const fn narrow(n: usize) -> u16 {
    if n > u16::MAX as usize {
        u16::MAX
    } else {
        n as u16
    }
}

/// Where an image comes from, written into a version-2 header by
/// [`encode_for`](super::encode_for): which unit it calibrates, which tool wrote it and when.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Provenance {
    /// The unit's ID (serial number), as the recordings name it; empty: not said.
    pub unit_id: String<UNIT_ID_LEN>,
    /// The writing tool's version, e.g. `0.1.0`; empty: not said.
    pub tool_version: String<TOOL_VERSION_LEN>,
    /// The date written, `YYYYMMDD` as a number (`20261128`); 0: not said.
    pub date: u32,
}

impl Provenance {
    /// A provenance from text, refused (naming the field) where a field is longer than the
    /// header holds: [`UNIT_ID_LEN`] bytes of unit ID, [`TOOL_VERSION_LEN`] of tool version.
    pub fn new(unit_id: &str, tool_version: &str, date: u32) -> Result<Self, BlobError> {
        Ok(Self {
            unit_id: text(unit_id, "unit ID")?,
            tool_version: text(tool_version, "tool version")?,
            date,
        })
    }
}

fn text<const N: usize>(value: &str, field: &'static str) -> Result<String<N>, BlobError> {
    String::try_from(value).map_err(|_| BlobError::TooLong {
        field,
        len: value.len(),
        max: N,
    })
}

/// An image's header, read without its payload ([`header`](super::header)).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Header {
    /// Format version, [`VERSION_1`](super::VERSION_1), [`VERSION_2`] or
    /// [`VERSION_3`](super::VERSION_3).
    pub version: u16,
    /// Model kind byte ([`Kind`](super::Kind)).
    pub kind: u8,
    /// Payload length, bytes.
    pub payload_len: u32,
    /// What the model needs; `None` in a version-1 image (which does not say).
    pub needs: Option<Capacities>,
    /// Where the image comes from (empty in a version-1 image).
    pub provenance: Provenance,
}

impl Header {
    /// Bytes before the payload.
    pub fn len(&self) -> usize {
        header_len(self.version)
    }

    /// Always false: a header is never empty (for clippy's `len_without_is_empty`).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The whole image's length: header, payload and CRC.
    pub fn image_len(&self) -> usize {
        self.len()
            .saturating_add(self.payload_len as usize)
            .saturating_add(TRAILER_LEN)
    }
}

/// Reads the header at the start of `bytes`: magic, version, that the header is whole, and the
/// provenance's text.
pub(super) fn read(bytes: &[u8]) -> Result<Header, BlobError> {
    let mut header = read_fixed(bytes)?;
    if header.version >= VERSION_2 {
        header.provenance = Provenance {
            unit_id: label(bytes, UNIT_AT, "unit ID")?,
            tool_version: label(bytes, TOOL_AT, "tool version")?,
            date: le_u32(bytes, DATE_AT),
        };
    }
    Ok(header)
}

/// [`read`] without the provenance (left empty): what decoding needs, without the UTF-8
/// validation of the labels in the firmware's code.
pub(super) fn read_fixed(bytes: &[u8]) -> Result<Header, BlobError> {
    match array::<4>(bytes, 0) {
        Some([0xff, 0xff, 0xff, 0xff]) => return Err(BlobError::Erased),
        Some(found) if found != MAGIC => return Err(BlobError::BadMagic { found }),
        Some(_) => {}
        None => {
            return Err(BlobError::Truncated {
                needed: HEADER_LEN_V1,
                found: bytes.len(),
            })
        }
    }
    let version = le_u16(bytes, 4);
    let len = header_len(version);
    if len == 0 {
        return Err(BlobError::UnsupportedVersion { found: version });
    }
    if bytes.len() < len {
        return Err(BlobError::Truncated {
            needed: len.saturating_add(TRAILER_LEN),
            found: bytes.len(),
        });
    }
    let mut header = Header {
        version,
        kind: bytes.get(KIND_AT).copied().unwrap_or(0),
        payload_len: le_u32(bytes, PAYLOAD_LEN_AT),
        needs: None,
        provenance: Provenance::default(),
    };
    if version >= VERSION_2 {
        header.needs = Some(Capacities {
            reference_times: le_u16(bytes, CAPACITIES_AT),
            ambients: le_u16(bytes, CAPACITIES_AT.saturating_add(2)),
            curves: le_u16(bytes, CAPACITIES_AT.saturating_add(4)),
        });
    }
    Ok(header)
}

/// A zero-padded UTF-8 field of `N` bytes at `at`.
fn label<const N: usize>(
    bytes: &[u8],
    at: usize,
    field: &'static str,
) -> Result<String<N>, BlobError> {
    let raw = array::<N>(bytes, at).unwrap_or([0; N]);
    let used = raw.iter().position(|&b| b == 0).unwrap_or(N);
    core::str::from_utf8(raw.get(..used).unwrap_or_default())
        .ok()
        .and_then(|text| String::try_from(text).ok())
        .ok_or(BlobError::BadHeader { field })
}

/// Writes the header of the version this build writes ([`FORMAT_VERSION`],
/// version 2's layout) into `out` (exactly [`HEADER_LEN_V2`] bytes).
pub(super) fn write(
    out: &mut [u8],
    kind: u8,
    payload_len: u32,
    needs: &Capacities,
    provenance: &Provenance,
) {
    out.fill(0);
    let fields: [(usize, &[u8]); 10] = [
        (0, &MAGIC),
        (4, &FORMAT_VERSION.to_le_bytes()),
        (KIND_AT, &[kind]),
        (PAYLOAD_LEN_AT, &payload_len.to_le_bytes()),
        (CAPACITIES_AT, &needs.reference_times.to_le_bytes()),
        (
            CAPACITIES_AT.saturating_add(2),
            &needs.ambients.to_le_bytes(),
        ),
        (CAPACITIES_AT.saturating_add(4), &needs.curves.to_le_bytes()),
        (DATE_AT, &provenance.date.to_le_bytes()),
        (TOOL_AT, provenance.tool_version.as_bytes()),
        (UNIT_AT, provenance.unit_id.as_bytes()),
    ];
    for (at, field) in fields {
        if let Some(place) = out.get_mut(at..) {
            for (dst, src) in place.iter_mut().zip(field) {
                *dst = *src;
            }
        }
    }
}
