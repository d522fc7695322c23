//! The `source` argument of `fit` and `evaluate`: recording files (a campaign folder, a folder of
//! `.mcap` files, one file, or a list of files) or recordings and segments already in memory.

use std::path::PathBuf;
use std::sync::Arc;

use drift_evaluate::pipeline::recording_files;
use drift_recording::Segment;
use pyo3::prelude::*;

use crate::arrays::describe;
use crate::errors::Error;
use crate::recording::PyRecording;
use crate::segment::PySegment;

/// Where the activations come from.
pub enum Source {
    /// Recording files, read by drift-fit's pipeline (calibration files only when fitting).
    Files(Vec<PathBuf>),
    /// Activations in memory (shared with their Python objects, not copied).
    Segments(Vec<Arc<Segment>>),
}

const EXPECTED: &str = "a path (campaign folder, folder of .mcap files or one .mcap file), a \
                        gyrodrift.Recording or Segment, or a list of them";

fn files_at(path: PathBuf) -> Result<Vec<PathBuf>, Error> {
    if path.is_file() {
        Ok(vec![path])
    } else {
        Ok(recording_files(&path)?)
    }
}

fn objects(py: Python<'_>, item: &Bound<'_, PyAny>, into: &mut Vec<Arc<Segment>>) -> bool {
    if let Ok(recording) = item.cast::<PyRecording>() {
        into.extend(recording.get().segment_arcs(py));
        true
    } else if let Ok(segment) = item.cast::<PySegment>() {
        into.push(Arc::clone(&segment.get().segment));
        true
    } else {
        false
    }
}

/// Reads `source` (named `name` in errors).
pub fn source(py: Python<'_>, name: &str, value: &Bound<'_, PyAny>) -> Result<Source, Error> {
    let wrong = || {
        Error::Input(format!(
            "`{name}` must be {EXPECTED}, got {}",
            describe(value)
        ))
    };
    if let Ok(path) = value.extract::<PathBuf>() {
        return files_at(path).map(Source::Files);
    }
    let mut segments = Vec::new();
    if objects(py, value, &mut segments) {
        return Ok(Source::Segments(segments));
    }
    let items: Vec<Bound<'_, PyAny>> = value.extract().map_err(|_| wrong())?;
    let mut files = Vec::new();
    for (i, item) in items.iter().enumerate() {
        if let Ok(path) = item.extract::<PathBuf>() {
            files.push(path);
        } else if !objects(py, item, &mut segments) {
            return Err(Error::Input(format!(
                "`{name}[{i}]` must be a path, gyrodrift.Recording or Segment, got {}",
                describe(item)
            )));
        }
    }
    match (files.is_empty(), segments.is_empty()) {
        (false, true) => Ok(Source::Files(files)),
        (true, false) => Ok(Source::Segments(segments)),
        (false, false) => Err(Error::Input(format!(
            "`{name}` must hold paths or recordings/segments, not both"
        ))),
        (true, true) => Err(Error::Input(format!(
            "`{name}` must not be empty ({EXPECTED})"
        ))),
    }
}

/// A list of set points in °C (finite floats), non-empty unless `allow_empty`.
pub fn set_points(
    name: &str,
    value: &Bound<'_, PyAny>,
    allow_empty: bool,
) -> Result<Vec<f64>, Error> {
    let points: Vec<f64> =
        crate::args::value(name, "a sequence of set points in °C (floats)", value)?;
    if let Some(bad) = points.iter().find(|p| !p.is_finite()) {
        return Err(Error::Input(format!(
            "`{name}` must hold finite set points, got {bad}"
        )));
    }
    if points.is_empty() && !allow_empty {
        return Err(Error::Input(format!(
            "`{name}` must name at least one set point"
        )));
    }
    Ok(points)
}
