//! Image payloads across format versions: version 3's settings end with `sample_rate_hz`, which
//! versions 1 and 2 lack; every other byte is the same.

/// `new` is `old` (a version-1 or -2 payload) with `rate_hz` inserted after the settings' first
/// five fields: four `f32` (16 bytes) and the varint of `stuck_after_samples`.
pub fn assert_is_v2_with_rate(old: &[u8], new: &[u8], rate_hz: f32) {
    let varint = old[16..].iter().position(|byte| byte & 0x80 == 0).unwrap() + 1;
    let at = 16 + varint;
    assert_eq!(new.len(), old.len() + 4);
    assert_eq!(new[..at], old[..at]);
    assert_eq!(new[at..at + 4], rate_hz.to_le_bytes());
    assert_eq!(new[at + 4..], old[at..]);
}
