//! Target `recording`: the MCAP recording reader, from bytes
//! ([`drift_recording::read_recording_bytes`], which [`drift_recording::read_recording`] calls).
//!
//! Invariants: never panics; an error names the file; an accepted recording is consistent
//! (every per-sample array of a segment has the segment's length, indices count from 0, no
//! non-finite rate), and its gyro data and labels survive a write → read round trip unchanged.

use std::path::Path;

use drift_recording::{read_recording_bytes, Recording};

/// The name errors must carry.
pub const NAME: &str = "fuzz-input.mcap";

fn check_consistent(recording: &Recording) {
    for (k, s) in recording.segments.iter().enumerate() {
        let n = s.len();
        assert!(n > 0, "segment {k} is empty");
        assert!(
            s.rate_dps.iter().all(|v| v.len() == n)
                && s.temperature_raw.iter().all(|v| v.len() == n),
            "segment {k}: axis lengths differ"
        );
        assert!(
            s.since_power_on
                .iter()
                .enumerate()
                .all(|(i, &x)| x as usize == i),
            "segment {k}: sample indices do not count from 0"
        );
        assert!(
            s.rate_dps.iter().flatten().all(|v| v.is_finite()),
            "segment {k}: non-finite rate accepted"
        );
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    match read_recording_bytes(Path::new(NAME), data) {
        Err(error) => {
            let text = error.to_string();
            assert!(text.contains(NAME), "error does not name the file: {text}");
        }
        Ok(recording) => {
            check_consistent(&recording);
            round_trip(&recording);
        }
    }
}

/// What a reader accepts, the writer writes and the reader reads back identically.
pub fn round_trip(recording: &Recording) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("temporary folder: {e}"));
    let path = dir.path().join("round-trip.mcap");
    if let Err(error) = drift_recording::write_recording(recording, &path) {
        panic!("an accepted recording does not write: {error}");
    }
    let again = drift_recording::read_recording(&path)
        .unwrap_or_else(|e| panic!("a written recording does not read back: {e}"));
    assert_eq!(again.segments.len(), recording.segments.len());
    for (a, b) in again.segments.iter().zip(&recording.segments) {
        // Gyro data and labels; auxiliary channels are carried as batched, not checked against
        // the gyro sample count by the reader, so they are not compared.
        assert_eq!(
            (&a.labels, &a.rate_dps, &a.temperature_raw, a.power_on_ns),
            (&b.labels, &b.rate_dps, &b.temperature_raw, b.power_on_ns),
            "round trip changed a segment"
        );
    }
}
