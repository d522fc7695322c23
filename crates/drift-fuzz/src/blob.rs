//! Target `blob`: the firmware table image decoder, for both model kinds and two capacities.
//!
//! Input: one mode byte, then the image. Mode bit 0 rewrites the declared payload length and
//! bit 1 recomputes the CRC before decoding (the header's length read from its version byte), so mutations reach the postcard payload and the
//! model validation behind the checksum instead of all dying at the CRC check.
//!
//! Invariants: decoding never panics; an accepted image validates, runs a corrector, and
//! survives encode → decode unchanged (images are not canonical: finding F1).

use drift_core::blob::{
    decode, decode_into, encode, header_len, Image, HEADER_LEN, HEADER_LEN_V1, TRAILER_LEN,
    VERSION_3,
};
use drift_core::{Corrector, ModifiedTables, PolynomialTables, Sample};

const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Fixes the declared length and/or the CRC of `bytes` as the mode byte asks.
pub fn prepare(mode: u8, bytes: &mut [u8]) {
    let len = bytes.len();
    if len < HEADER_LEN_V1 + TRAILER_LEN {
        return;
    }
    // The version's header length (version 1's for an unknown version), as the decoder reads it.
    let header = match header_len(u16::from_le_bytes([bytes[4], bytes[5]])) {
        0 => HEADER_LEN_V1,
        known => known,
    };
    let body = len - TRAILER_LEN;
    if mode & 1 != 0 && body >= header {
        let payload = u32::try_from(body - header).unwrap_or(u32::MAX);
        bytes[8..12].copy_from_slice(&payload.to_le_bytes());
    }
    if mode & 2 != 0 {
        let crc = CRC32.checksum(&bytes[..body]);
        bytes[body..].copy_from_slice(&crc.to_le_bytes());
    }
}

/// Decodes `bytes` as an `M`; whatever decodes must validate, re-encode and correct. The in-place
/// decoder (the firmware's) must give the same model or the same error.
fn check<M: Image + PartialEq + core::fmt::Debug + Default>(bytes: &[u8]) {
    let decoded = decode::<M>(bytes);
    let mut place = M::default();
    let in_place = decode_into(bytes, &mut place);
    match (&decoded, &in_place) {
        (Ok(model), Ok(())) => assert_eq!(&place, model, "decode_into gives another model"),
        (Err(a), Err(b)) => assert_eq!(a, b, "decode_into gives another error"),
        _ => panic!("decode gave {decoded:?}, decode_into {in_place:?}"),
    }
    let Ok(model) = decoded else {
        return;
    };
    assert!(model.validate().is_ok(), "decoded model fails validation");
    let mut buffer = vec![0; bytes.len() + 64];
    let len = encode(&model, &mut buffer).expect("a decoded model re-encodes");
    // Finding F1 (docs/reliability.md): images are not canonical (the reserved header byte is
    // ignored, postcard accepts overlong varints), so several byte strings decode to one model.
    // The CRC still covers every byte. What must hold: the model survives encode → decode, and the
    // canonical image is never longer than the one decoded.
    // A version-1 image is re-encoded behind the longer header, and a version-1 or -2 payload
    // gains its settings' sample rate (an `f32`).
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    let rate = if version < VERSION_3 { 4 } else { 0 };
    let grown = HEADER_LEN - header_len(version) + rate;
    assert!(
        len <= bytes.len() + grown,
        "re-encoding is longer than the image"
    );
    let again = decode::<M>(&buffer[..len]).expect("a re-encoded model decodes");
    assert_eq!(again, model, "the model changes through encode → decode");
    let mut corrector = Corrector::new(&model).expect("a decoded model is accepted");
    corrector
        .power_on([6000.0; 3])
        .expect("finite switch-on is accepted");
    for ms in [0, 1, 10_000, 200_000] {
        let out = corrector.correct(&Sample {
            since_power_on_ms: ms,
            rate_dps: [0.1; 3],
            temperature_raw: [6100.0; 3],
        });
        assert!(out.corrected_dps.iter().all(|v| v.is_finite()), "{out:?}");
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Some((&mode, image)) = data.split_first() else {
        return;
    };
    let mut bytes = image.to_vec();
    prepare(mode, &mut bytes);
    check::<ModifiedTables>(&bytes);
    // A small firmware capacity: over-capacity counts must be refused, not truncated.
    check::<ModifiedTables<8, 4, 8>>(&bytes);
    check::<PolynomialTables>(&bytes);
}
