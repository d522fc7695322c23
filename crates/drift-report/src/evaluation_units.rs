//! Evaluation data in another unit than the calibration data. The tables correct what they were
//! fitted on; a recording of the evaluation data written in another rate unit (rad/s read as °/s,
//! or a scaled log) is judged without a word, its drift tens of times the calibration's. Its
//! uncorrected drift against the calibration's says so: a warning naming the file, printed and in
//! the report.

use std::path::{Path, PathBuf};

use drift_evaluate::evaluate::{spread, ModelKind};
use drift_evaluate::pipeline::Outcome;
use drift_recording::read_metadata;

/// How far (×) a recording's median uncorrected drift may stand from the calibration's before it
/// is taken for another unit: rad/s against °/s is 57×; set points, off-times and field ramps of
/// one sensor move it by a few.
pub const OTHER_UNIT_RATIO: f64 = 15.0;

fn median(mut values: Vec<f64>) -> Option<f64> {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let mid = values.len() / 2;
    Some(if values.len() % 2 == 0 {
        (values[mid - 1] + values[mid]) / 2.0
    } else {
        values[mid]
    })
}

/// Whether a result of `labels` belongs to the recording whose metadata is `metadata`: its unit,
/// and its set point and kind where the metadata give them.
fn belongs(
    labels: &drift_recording::SegmentLabels,
    metadata: &std::collections::BTreeMap<String, String>,
) -> bool {
    let unit = metadata.get("unit_id").is_none_or(|u| *u == labels.unit_id);
    let set_point = metadata
        .get("set_point_celsius")
        .and_then(|v| v.parse::<f64>().ok())
        .is_none_or(|s| (s - labels.nominal_set_point_celsius()).abs() < 1e-6);
    let kind = metadata
        .get("series_kind")
        .is_none_or(|k| k == labels.series_kind.as_str());
    unit && set_point && kind
}

/// One warning per recording of `evaluation` whose median uncorrected drift (over its activations
/// and axes) is more than [`OTHER_UNIT_RATIO`]× from the calibration activations' median.
pub fn warnings(outcome: &Outcome, evaluation: &[PathBuf]) -> Vec<String> {
    let calibration = median(
        outcome
            .calibration
            .iter()
            .flat_map(|a| {
                a.drift_dps
                    .iter()
                    .map(|axis| spread(axis.iter().map(|&v| f64::from(v))))
            })
            .collect(),
    );
    let Some(calibration) = calibration.filter(|c| *c > 0.0) else {
        return Vec::new();
    };
    evaluation
        .iter()
        .filter_map(|file| warning(outcome, file, calibration))
        .collect()
}

fn warning(outcome: &Outcome, file: &Path, calibration: f64) -> Option<String> {
    let metadata = read_metadata(file).ok()?;
    let drift = median(
        outcome
            .results
            .iter()
            .filter(|(_, r)| belongs(&r.labels, &metadata))
            .flat_map(|(_, r)| {
                r.models
                    .iter()
                    .filter(|m| m.model == ModelKind::Uncorrected)
            })
            .flat_map(|m| m.drift_dps)
            .collect(),
    )?;
    let ratio = drift / calibration;
    if (1.0 / OTHER_UNIT_RATIO..=OTHER_UNIT_RATIO).contains(&ratio) {
        return None;
    }
    let how = if ratio > 1.0 {
        format!("{ratio:.0}× the calibration data's")
    } else {
        format!("{:.0}× less than the calibration data's", 1.0 / ratio)
    };
    Some(format!(
        "--evaluation-data: `{}`: uncorrected drift {drift:.4} °/s (median over its activations and axes), {how} {calibration:.4} °/s: its rate is likely in another unit or scale (rad/s against °/s is 57×); its results are in the report as read",
        file.display()
    ))
}
