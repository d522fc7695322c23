//! The loop's activations, read one at a time and kept as 0.1-s block means.
//!
//! Everything the loop computes looks through the fit's 1-s low-pass: the residual, the
//! candidates, what the tables absorb of them, the drift metric. A 1-s mean of ten 0.1-s block
//! means is the 1-s mean of the samples they cover ([`drift_recording::block_means`]), so the loop
//! works on a hundredth of a 1 kHz recording's samples and never holds a recording whole.

use std::collections::BTreeMap;
use std::path::PathBuf;

use drift_fit::FitSettings;
use drift_recording::{block_means, OpenRecording, Progress, ReadError, Segment, Within};

/// The rate the loop works at, Hz: ten block means per second of the fit's 1-s window.
pub const DIAGNOSIS_RATE_HZ: u32 = 10;

/// `segment` at [`DIAGNOSIS_RATE_HZ`], or as it is where its rate is not a multiple of it (the
/// loop then runs at the recorded rate, only slower).
pub fn at_diagnosis_rate(segment: Segment) -> Segment {
    block_means(&segment, DIAGNOSIS_RATE_HZ).unwrap_or(segment)
}

/// `settings` for activations at [`DIAGNOSIS_RATE_HZ`]: the analysis grid a whole number of their
/// samples (the default 10 ms grid rounded up to their 100 ms), everything else as given. The
/// loop's tables, its candidates' and the extended model's are all fitted with these.
pub fn loop_settings(settings: &FitSettings) -> FitSettings {
    let spacing_ms = 1000 / DIAGNOSIS_RATE_HZ;
    FitSettings {
        grid_ms: settings.grid_ms.max(1).div_ceil(spacing_ms) * spacing_ms,
        ..settings.clone()
    }
}

/// The step [`read_by_unit`] reports.
pub const READ_BY_ROLE: &str = "reading activations by role";

/// Every activation of `files`, by unit, in file and recording order, at the diagnosis rate:
/// each recording is decoded one activation at a time, and only its block means are kept.
/// `progress` is told each file done ([`READ_BY_ROLE`]) and asked between activations whether to
/// go on ([`ReadError::Interrupted`] when not).
pub fn read_by_unit(
    files: &[PathBuf],
    progress: &dyn Progress,
) -> Result<BTreeMap<String, Vec<Segment>>, ReadError> {
    let mut by_unit: BTreeMap<String, Vec<Segment>> = BTreeMap::new();
    let total = files.len() as u64;
    for (i, path) in files.iter().enumerate() {
        let done = i as u64;
        let within = Within {
            outer: progress,
            step: READ_BY_ROLE,
            done,
            total,
        };
        if progress.check(READ_BY_ROLE, done, total).is_err() {
            return Err(ReadError::Interrupted { path: path.clone() });
        }
        let recording = OpenRecording::open(path)?;
        let mut activations = Vec::new();
        let unit = recording.unit_id().to_owned();
        recording.for_each_activation_with(
            |segment| {
                activations.push(at_diagnosis_rate(segment));
                true
            },
            &within,
        )?;
        by_unit.entry(unit).or_default().extend(activations);
    }
    Ok(by_unit)
}
