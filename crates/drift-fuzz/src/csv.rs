//! Target `csv`: the CSV reader for measured data ([`drift_recording::read_csv_bytes`], which
//! [`drift_recording::read_csv`] calls after decompressing).
//!
//! Input: one byte picks the options (strict fixed-rate rows, or resampled host timestamps; with
//! or without accepting temperature dropouts), then the CSV text.
//!
//! Invariants: never panics; every error names the file; an accepted file gives activations whose
//! arrays agree in length, whose rates are finite, and which write to MCAP and read back unchanged.

use std::path::Path;

use drift_recording::{read_csv_bytes, CsvOptions, CsvTiming};

/// The name errors must carry.
pub const NAME: &str = "fuzz-input.csv";

/// Runs one input.
pub fn run(data: &[u8]) {
    let Some((&mode, text)) = data.split_first() else {
        return;
    };
    let options = CsvOptions {
        sample_rate_hz: if mode & 1 == 0 { 100 } else { 1000 },
        timing: if mode & 2 == 0 {
            CsvTiming::Strict
        } else {
            CsvTiming::Resample { max_gap_s: 0.5 }
        },
        temperature_dropouts: mode & 4 != 0,
        ..CsvOptions::default()
    };
    match read_csv_bytes(Path::new(NAME), text, &options) {
        Err(error) => {
            let message = error.to_string();
            assert!(
                message.contains(NAME),
                "error does not name the file: {message}"
            );
        }
        Ok(recording) => {
            for (k, s) in recording.segments.iter().enumerate() {
                let n = s.len();
                assert!(n > 0, "activation {k} is empty");
                assert!(
                    s.rate_dps.iter().all(|v| v.len() == n)
                        && s.temperature_raw.iter().all(|v| v.len() == n),
                    "activation {k}: axis lengths differ"
                );
                assert!(
                    s.rate_dps.iter().flatten().all(|v| v.is_finite()),
                    "activation {k}: non-finite rate"
                );
                assert!(
                    s.labels.set_point_celsius.is_finite(),
                    "activation {k}: set point"
                );
            }
            crate::recording::round_trip(&recording);
        }
    }
}
