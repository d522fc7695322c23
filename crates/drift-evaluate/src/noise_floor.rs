//! The noise floor of a zero-drift twin: what is left of its activations, uncorrected, once each
//! unit's constant bias is taken out. Every figure of the error is reported beside it, per group
//! of activations recorded alike (set point and series kind).

use std::collections::BTreeMap;
use std::path::Path;

use drift_recording::{read_recording, Segment};

use crate::evaluate::{mean_floor, noise_floor_per_activation};
use crate::pipeline::{self, PipelineError};

/// The noise floor per group of activations (`+33.0 °C field`, as [`group_name`] names it).
pub type Floor = BTreeMap<String, FloorGroup>;

/// The noise floor of one held-out group.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FloorGroup {
    /// Per axis, (drift, RMS) of the 1-s mean, °/s: the mean over the twin's units of each unit's
    /// mean over its activations.
    pub mean: [(f64, f64); 3],
    /// Per axis, the drift of every twin activation in the group, °/s: what the interval of an
    /// excess cut resamples ([`crate::excess`]).
    pub drift: [Vec<f64>; 3],
}

/// The group an activation's result goes in.
pub fn group_name(set_point_celsius: f64, series_kind: &str) -> String {
    format!("{set_point_celsius:+.1} °C {series_kind}")
}

/// Measures the noise floor on the zero-drift campaign in `dir`, recorded like the diagnosed one:
/// per unit, set point and series kind, its activations uncorrected, less the unit's constant bias
/// ([`crate::evaluate::noise_floor`]); the mean
/// over its units.
pub fn measure(dir: &Path, window_s: f64) -> Result<Floor, PipelineError> {
    let mut groups: BTreeMap<(String, String), Vec<Segment>> = BTreeMap::new();
    for path in pipeline::recording_files(dir)? {
        let recording = read_recording(&path)?;
        for segment in recording.segments {
            let key = group_name(
                segment.labels.nominal_set_point_celsius(),
                segment.labels.series_kind.as_str(),
            );
            groups
                .entry((key, recording.unit_id.clone()))
                .or_default()
                .push(segment);
        }
    }
    let mut sums: BTreeMap<String, (FloorGroup, usize)> = BTreeMap::new();
    for ((key, _unit), segments) in &groups {
        let refs: Vec<&Segment> = segments.iter().collect();
        let per_activation = noise_floor_per_activation(&refs, window_s);
        let entry = sums.entry(key.clone()).or_default();
        for (sum, (drift, rms)) in entry.0.mean.iter_mut().zip(mean_floor(&per_activation)) {
            sum.0 += drift;
            sum.1 += rms;
        }
        for per_axis in per_activation {
            for (all, (drift, _)) in entry.0.drift.iter_mut().zip(per_axis) {
                all.push(drift);
            }
        }
        entry.1 += 1;
    }
    if sums.is_empty() {
        return Err(PipelineError::NoRecordings {
            path: dir.to_owned(),
        });
    }
    Ok(sums
        .into_iter()
        .map(|(key, (mut group, n))| {
            group.mean = group.mean.map(|(d, r)| (d / n as f64, r / n as f64));
            (key, group)
        })
        .collect())
}
