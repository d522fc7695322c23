//! Image format version 2: the header's capacities, provenance and length, a committed image, and
//! the decoder paths version 2 added, which never panic.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(clippy::arithmetic_side_effects, missing_docs)]

mod common;

use common::fixture::{self, FixtureTables};
use drift_core::blob::{
    decode, decode_into, encode, encode_for, header, image_len, BlobError, Capacities, Header,
    Provenance, FORMAT_VERSION, HEADER_LEN, HEADER_LEN_V1, VERSION_1, VERSION_2,
};
use drift_core::{ModifiedTables, PolynomialTables};
use proptest::prelude::*;

fn provenance() -> Provenance {
    Provenance {
        unit_id: "unit-07".try_into().unwrap(),
        tool_version: "0.1.0".try_into().unwrap(),
        date: 20_261_128,
    }
}

fn image_for(provenance: &Provenance) -> Vec<u8> {
    let mut buffer = vec![0; 64 * 1024];
    let len = encode_for(&fixture::modified(), provenance, &mut buffer).unwrap();
    buffer.truncate(len);
    buffer
}

fn reseal(bytes: &mut [u8]) {
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);
    let body = bytes.len() - 4;
    let sum = crc.checksum(&bytes[..body]);
    bytes[body..].copy_from_slice(&sum.to_le_bytes());
}

/// The committed version-2 image of the paper's fixture with a provenance (written by version 2's
/// encoder, never rewritten): it loads into the tables it held (the sample rate not stated), its
/// header says what it holds, and today's image of the same tables is the same but for the
/// version and the settings' `sample_rate_hz`.
#[test]
fn the_committed_v2_image_still_loads() {
    const PATH: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/image-v2-modified.bin"
    );
    let committed = std::fs::read(PATH).unwrap();
    assert_eq!(
        header(&committed).unwrap(),
        Header {
            version: VERSION_2,
            kind: 1,
            payload_len: u32::try_from(committed.len() - HEADER_LEN - 4).unwrap(),
            needs: Some(Capacities {
                reference_times: 8,
                ambients: 3,
                curves: 16,
            }),
            provenance: provenance(),
        }
    );
    let tables = decode::<FixtureTables>(&committed).unwrap();
    assert_eq!(tables, fixture::modified());
    assert_eq!(tables.settings.sample_rate_hz.to_bits(), 0);
    let today = image_for(&provenance());
    assert_eq!(u16::from_le_bytes([today[4], today[5]]), FORMAT_VERSION);
    // Kind, capacities and provenance alike; the payload is 4 bytes longer.
    assert_eq!(today[6..8], committed[6..8]);
    assert_eq!(today[12..HEADER_LEN], committed[12..HEADER_LEN]);
    let v2_payload = &committed[HEADER_LEN..committed.len() - 4];
    let v3_payload = &today[HEADER_LEN..today.len() - 4];
    common::legacy::assert_is_v2_with_rate(v2_payload, v3_payload, 0.0);
}

#[test]
fn a_version_1_header_says_no_capacities_and_no_provenance() {
    let v1 = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../testdata/image-v1-modified.bin"
    ))
    .unwrap();
    let read = header(&v1).unwrap();
    assert_eq!((read.version, read.kind), (VERSION_1, 1));
    assert_eq!(read.needs, None);
    assert_eq!(read.provenance, Provenance::default());
    assert_eq!(read.len(), HEADER_LEN_V1);
    assert_eq!(image_len(&v1).unwrap(), v1.len());
    // Too small a build still fails on a version-1 image, as the payload decoder finds out.
    assert!(matches!(
        decode::<ModifiedTables<8, 3, 8>>(&v1),
        Err(BlobError::Malformed(_))
    ));
}

/// Each dimension too small for the image is named with what it needs; the in-place decoder says
/// the same, before touching the tables.
#[test]
fn capacity_errors_name_the_capacity_needed() {
    let image = image_for(&provenance());
    let expect = |what, needed, capacity| BlobError::Capacity {
        what,
        needed,
        capacity,
    };
    assert_eq!(
        decode::<ModifiedTables<7, 3, 16>>(&image),
        Err(expect("reference times (R)", 8, 7))
    );
    assert_eq!(
        decode::<ModifiedTables<8, 2, 16>>(&image),
        Err(expect("ambients (A)", 3, 2))
    );
    let mut small: ModifiedTables<8, 3, 15> = ModifiedTables::EMPTY;
    assert_eq!(
        decode_into(&image, &mut small),
        Err(expect("curves per ambient (C)", 16, 15))
    );
    let message = expect("curves per ambient (C)", 16, 15).to_string();
    assert!(
        message.contains("needs 16 curves per ambient (C)") && message.contains("hold 15"),
        "{message}"
    );
    // Capacities exactly the image's suffice.
    assert!(decode::<ModifiedTables<8, 3, 16>>(&image).is_ok());
}

/// Firmware reads the image out of an erased flash sector: the header gives its length, and a
/// sector with no image says so.
#[test]
fn an_image_is_read_from_an_erased_flash_sector() {
    let image = image_for(&provenance());
    let mut sector = vec![0xff_u8; 16 * 1024];
    sector[..image.len()].copy_from_slice(&image);
    let len = image_len(&sector).unwrap();
    assert_eq!(len, image.len());
    let mut tables: FixtureTables = ModifiedTables::EMPTY;
    decode_into(&sector[..len], &mut tables).unwrap();
    assert_eq!(tables, fixture::modified());
    // The whole sector is not an image: the padding is named as trailing bytes.
    assert_eq!(
        decode::<FixtureTables>(&sector),
        Err(BlobError::TrailingBytes {
            count: sector.len() - image.len()
        })
    );
    assert_eq!(image_len(&[0xff; 4096]), Err(BlobError::Erased));
    assert_eq!(
        decode::<FixtureTables>(&[0xff; 4096]),
        Err(BlobError::Erased)
    );
    assert!(BlobError::Erased.to_string().contains("erased flash"));
}

#[test]
fn a_header_field_that_is_not_utf8_is_named() {
    let mut image = image_for(&provenance());
    image[40] = 0xc3; // a UTF-8 lead byte with no continuation, in the unit ID
    image[41] = b'(';
    reseal(&mut image);
    assert_eq!(
        header(&image),
        Err(BlobError::BadHeader { field: "unit ID" })
    );
    // Decoding needs no provenance (and firmware carries no UTF-8 validation for it).
    assert_eq!(
        decode::<FixtureTables>(&image).unwrap(),
        fixture::modified()
    );
}

#[test]
fn polynomial_images_need_no_capacities() {
    let mut buffer = vec![0; 4096];
    let len = encode(&fixture::standard(), &mut buffer).unwrap();
    assert_eq!(
        header(&buffer[..len]).unwrap().needs,
        Some(Capacities::NONE)
    );
    assert_eq!(
        decode::<PolynomialTables>(&buffer[..len]).unwrap(),
        fixture::standard()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(if cfg!(miri) { 4 } else { 1000 }))]

    /// A version-2 header with arbitrary capacities, provenance bytes and declared length, resealed,
    /// and arbitrary bytes after it: the header reader, the length helper and both decoders return,
    /// never panic, and agree on what they refuse.
    #[test]
    fn the_v2_header_paths_never_panic(
        header_bytes in prop::collection::vec(any::<u8>(), 52),
        tail in prop::collection::vec(any::<u8>(), 0..300),
        keep_version in any::<bool>(),
    ) {
        let mut bytes = image_for(&provenance());
        bytes.truncate(12);
        if !keep_version {
            bytes[4] = header_bytes[0];
        }
        bytes.extend_from_slice(&header_bytes);
        bytes.extend_from_slice(&tail);
        for sealed in [false, true] {
            if sealed && bytes.len() >= 16 {
                reseal(&mut bytes);
            }
            let read = header(&bytes);
            let len = image_len(&bytes);
            if let Ok(read) = &read {
                prop_assert_eq!(len.clone(), Ok(read.image_len()));
            }
            let by_value = decode::<ModifiedTables<8, 3, 16>>(&bytes);
            let mut place: ModifiedTables<8, 3, 16> = ModifiedTables::EMPTY;
            let in_place = decode_into(&bytes, &mut place);
            prop_assert_eq!(by_value.map(|_| ()), in_place);
            let _ = decode::<PolynomialTables>(&bytes);
        }
    }

    /// Any amount of erased (or any other) bytes after an image: the length helper finds the image.
    #[test]
    fn the_length_helper_finds_the_image_in_any_padding(
        padding in prop::collection::vec(any::<u8>(), 0..200),
    ) {
        let image = image_for(&provenance());
        let mut sector = image.clone();
        sector.extend_from_slice(&padding);
        prop_assert_eq!(image_len(&sector), Ok(image.len()));
    }
}
