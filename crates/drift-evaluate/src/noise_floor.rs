//! The noise floor of a zero-drift twin: what is left of its activations, uncorrected, once each
//! unit's constant bias is taken out. Every figure of the error is reported beside it, per group
//! of activations recorded alike (set point and series kind).

use std::collections::BTreeMap;
use std::path::Path;

use drift_recording::{OpenRecording, Segment};

use crate::evaluate::{activation_floor, constant_bias, mean_floor, mean_rate};
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

/// Per axis, (drift, RMS) of one activation, °/s.
type PerAxis = [(f64, f64); 3];

/// The (group, unit) an activation of `unit` is measured in.
fn key(segment: &Segment, unit: &str) -> (String, String) {
    (
        group_name(
            segment.labels.nominal_set_point_celsius(),
            segment.labels.series_kind.as_str(),
        ),
        unit.to_owned(),
    )
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
    let files = pipeline::recording_files(dir)?;
    // Two passes, one activation in memory at a time (a twin campaign at 1 kHz is gigabytes): the
    // constant bias of each unit and group first, then each activation about it.
    let mut means: BTreeMap<(String, String), Vec<[f64; 3]>> = BTreeMap::new();
    for path in &files {
        let recording = OpenRecording::open(path)?;
        let unit = recording.unit_id().to_owned();
        recording.for_each_activation(|segment| {
            means
                .entry(key(&segment, &unit))
                .or_default()
                .push(mean_rate(&segment));
            true
        })?;
    }
    let offsets: BTreeMap<(String, String), [f64; 3]> = means
        .into_iter()
        .map(|(group, means)| (group, constant_bias(means.into_iter())))
        .collect();
    let mut groups: BTreeMap<(String, String), Vec<PerAxis>> = BTreeMap::new();
    for path in &files {
        let recording = OpenRecording::open(path)?;
        let unit = recording.unit_id().to_owned();
        recording.for_each_activation(|segment| {
            let group = key(&segment, &unit);
            let offset = offsets.get(&group).copied().unwrap_or_default();
            groups
                .entry(group)
                .or_default()
                .push(activation_floor(&segment, offset, window_s));
            true
        })?;
    }
    let mut sums: BTreeMap<String, (FloorGroup, usize)> = BTreeMap::new();
    for ((name, _unit), per_activation) in groups {
        let entry = sums.entry(name).or_default();
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
        .map(|(name, (mut group, n))| {
            group.mean = group.mean.map(|(d, r)| (d / n as f64, r / n as f64));
            (name, group)
        })
        .collect())
}
