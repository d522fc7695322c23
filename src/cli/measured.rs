//! Recordings the paper's method cannot be fitted on (measured data without a power-on warm-up, at
//! one ambient, without power cycles): the commands name what is missing instead of failing on a
//! side effect of it, and `report` characterises what the data does tell.

use std::collections::BTreeMap;
use std::path::PathBuf;

use drift_evaluate::measured::{
    characterise, obstacles_of, switch_on, Characterisation, MeasuredSettings, NotFittable,
};
use drift_evaluate::pipeline::PipelineError;
use drift_recording::{read_recording, Segment};

/// The units of `files` the paper's method cannot be fitted on, with what each lacks. Reads one
/// file at a time and keeps only each activation's switch-on summary.
pub fn unfittable(files: &[PathBuf]) -> anyhow::Result<Vec<NotFittable>> {
    let settings = MeasuredSettings::default();
    let mut by_unit: BTreeMap<String, (Vec<_>, usize)> = BTreeMap::new();
    for path in files {
        let recording = read_recording(path)?;
        let entry = by_unit.entry(recording.unit_id.clone()).or_default();
        entry.0.extend(
            recording
                .segments
                .iter()
                .filter_map(|s| switch_on(s, &settings)),
        );
        entry.1 += recording.segments.len();
    }
    Ok(by_unit
        .into_iter()
        .map(|(unit, (starts, activations))| NotFittable {
            unit,
            obstacles: obstacles_of(&starts, activations, &settings),
        })
        .filter(|n| !n.obstacles.is_empty())
        .collect())
}

/// Whether a pipeline error may come from data the method cannot use.
pub fn may_be_unfittable(error: &PipelineError) -> bool {
    matches!(
        error,
        PipelineError::NoCalibration { .. } | PipelineError::Fit(_)
    )
}

/// A pipeline error, explained: if the recordings lack what the paper's method needs, the error is
/// [`NotFittable`] (naming every missing thing, the fit's own message as context); otherwise the
/// pipeline's error as it was.
pub fn explain(error: PipelineError, files: &[PathBuf]) -> anyhow::Error {
    if !may_be_unfittable(&error) {
        return error.into();
    }
    match unfittable(files) {
        Ok(units) => match units.into_iter().next() {
            Some(not_fittable) => anyhow::Error::new(not_fittable).context(format!(
                "{error} — `gyrodrift report` on these recordings writes what the data can tell"
            )),
            None => error.into(),
        },
        Err(read) => anyhow::Error::new(error)
            .context(format!("checking the recordings also failed: {read:#}")),
    }
}

/// Characterises every unit of `files` (all of a unit's activations together).
pub fn characterise_files(files: &[PathBuf]) -> anyhow::Result<Vec<Characterisation>> {
    let settings = MeasuredSettings::default();
    let mut by_unit: BTreeMap<String, Vec<Segment>> = BTreeMap::new();
    for path in files {
        let recording = read_recording(path)?;
        by_unit
            .entry(recording.unit_id.clone())
            .or_default()
            .extend(recording.segments);
    }
    Ok(by_unit
        .iter()
        .map(|(unit, segments)| characterise(unit, segments, &settings))
        .collect())
}
