//! `gyrodrift.Recording`: one unit's recording (MCAP) — load, build from segments, save — and
//! `gyrodrift.load_campaign`. Reading and writing are drift-recording's; the GIL is released.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use drift_evaluate::pipeline::recording_files;
use drift_recording::{
    check_named_aux_channel, fixed_aux_unit, read_metadata, read_recording_with, write_recording,
    Recording, AUX_RATE_HZ,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args;
use crate::errors::Error;
use crate::interrupt;
use crate::segment::PySegment;

/// The format's own auxiliary channels (all at 100 Hz), which every segment written needs; any
/// other channel is written as a named channel of its own.
pub const FORMAT_CHANNELS: [&str; 5] = [
    "accel_x",
    "accel_y",
    "accel_z",
    "chamber_set_point",
    "supply_voltage",
];

/// One unit's recording: metadata and its activations in order.
#[pyclass(module = "gyrodrift", name = "Recording", frozen)]
pub struct PyRecording {
    pub(crate) path: Option<PathBuf>,
    pub(crate) metadata: BTreeMap<String, String>,
    pub(crate) unit_id: String,
    pub(crate) sample_rate_hz: u32,
    pub(crate) segments: Vec<Py<PySegment>>,
}

impl PyRecording {
    /// Wraps a recording read by drift-recording (its segments are moved, not copied).
    pub fn wrap(py: Python<'_>, recording: Recording) -> PyResult<Self> {
        let segments = recording
            .segments
            .into_iter()
            .map(|s| Py::new(py, PySegment::wrap(s)))
            .collect::<PyResult<_>>()?;
        Ok(Self {
            path: Some(recording.path),
            metadata: recording.metadata,
            unit_id: recording.unit_id,
            sample_rate_hz: recording.sample_rate_hz,
            segments,
        })
    }

    /// The segments, shared with their Python objects.
    pub fn segment_arcs(&self, py: Python<'_>) -> Vec<Arc<drift_recording::Segment>> {
        self.segments
            .iter()
            .map(|s| Arc::clone(&s.bind(py).get().segment))
            .collect()
    }
}

/// Reads one recording with the GIL released; Ctrl-C stops it between activations.
pub fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyRecording> {
    let recording = interrupt::run(py, None, |progress| read_recording_with(&path, progress))?
        .map_err(Error::from)?;
    PyRecording::wrap(py, recording)
}

/// Checks what the writer needs beyond a valid in-memory recording, as `InputError`s naming segment
/// and channel: the format's auxiliary channels, and any named ones (valid names, one unit per
/// name across the recording), each at 100 Hz with one value per 10 ms of the activation or none
/// (a channel the source did not record, as the reader gives it). A channel then reads back
/// exactly as it was built, so whatever a reader gives can be saved again.
fn check_writable(recording: &Recording) -> Result<(), Error> {
    let mut units: BTreeMap<&str, (&str, usize)> = BTreeMap::new();
    for (i, segment) in recording.segments.iter().enumerate() {
        let every = (segment.sample_rate_hz / AUX_RATE_HZ).max(1) as usize;
        let expected = segment.len().div_ceil(every);
        for (name, channel) in &segment.aux {
            if let Some(unit) = fixed_aux_unit(name) {
                if channel.unit != unit {
                    return Err(Error::Input(format!(
                        "segments[{i}]: channel {name:?} is in {:?}, the recording format stores it in {unit:?}",
                        channel.unit
                    )));
                }
                continue;
            }
            check_named_aux_channel(name)
                .map_err(|reason| Error::Input(format!("segments[{i}]: {reason}")))?;
            let (unit, first) = *units.entry(name).or_insert((&channel.unit, i));
            if unit != channel.unit {
                return Err(Error::Input(format!(
                    "segments[{i}]: channel {name:?} is in {:?}, segments[{first}] has it in {unit:?} \
                     (a recording stores one unit per channel)",
                    channel.unit
                )));
            }
        }
        for name in FORMAT_CHANNELS {
            if !segment.aux.contains_key(name) {
                return Err(Error::Input(format!(
                    "segments[{i}]: channel {name:?} is missing: the recording format stores {} at {AUX_RATE_HZ} Hz",
                    FORMAT_CHANNELS.join(", ")
                )));
            }
        }
        for (name, channel) in &segment.aux {
            // No values: a channel the source did not record, as every reader gives the format's
            // own channels of a file without them; it is written and read back empty.
            let length_ok = channel.values.is_empty() || channel.values.len() == expected;
            if channel.sample_rate_hz != AUX_RATE_HZ || !length_ok {
                return Err(Error::Input(format!(
                    "segments[{i}]: channel {name:?} must hold {expected} values at {AUX_RATE_HZ} Hz \
                     ({} samples at {} Hz) or none (not recorded), got {} values at {} Hz",
                    segment.len(),
                    segment.sample_rate_hz,
                    channel.values.len(),
                    channel.sample_rate_hz
                )));
            }
        }
    }
    Ok(())
}

/// Default metadata of a recording built in Python (the keys of docs/recording-format.md).
fn default_metadata(
    unit_id: &str,
    rate: u32,
    segments: &[Py<PySegment>],
    py: Python<'_>,
) -> BTreeMap<String, String> {
    let mut metadata = BTreeMap::from([
        ("format_version".to_owned(), "1".to_owned()),
        ("unit_id".to_owned(), unit_id.to_owned()),
        ("sample_rate_hz".to_owned(), rate.to_string()),
        ("aux_rate_hz".to_owned(), AUX_RATE_HZ.to_string()),
        ("temperature_raw_per_celsius".to_owned(), "200".to_owned()),
        (
            "source".to_owned(),
            format!("gyrodrift Python {}", env!("CARGO_PKG_VERSION")),
        ),
    ]);
    let labels: Vec<_> = segments
        .iter()
        .map(|s| &s.bind(py).get().segment.labels)
        .collect();
    if let Some(first) = labels.first() {
        // Only when every activation agrees: the fitter then picks files by metadata alone. The
        // set point the activations belong to (the session's, for ramped field segments read from
        // a file), so it reads back as their nominal one.
        let nominal = first.nominal_set_point_celsius();
        if labels
            .iter()
            .all(|l| l.nominal_set_point_celsius() == nominal)
        {
            metadata.insert("set_point_celsius".into(), nominal.to_string());
        }
        if labels.iter().all(|l| l.series_kind == first.series_kind) {
            metadata.insert("series_kind".into(), first.series_kind.as_str().into());
        }
    }
    metadata
}

#[pymethods]
impl PyRecording {
    /// A recording of one unit from its segments (in recording order: each switches on after the
    /// previous one switched off). `unit_id` defaults to the segments' own; `metadata` entries are
    /// added to (and override) the defaults, except `unit_id` and `sample_rate_hz`.
    #[new]
    #[pyo3(signature = (segments, *, unit_id = None, metadata = None))]
    fn new(
        py: Python<'_>,
        segments: &Bound<'_, PyAny>,
        unit_id: Option<&Bound<'_, PyAny>>,
        metadata: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let segments: Vec<Bound<'_, PySegment>> =
            args::value("segments", "a sequence of gyrodrift.Segment", segments)?;
        let unit_id: Option<String> = args::optional("unit_id", "a str", unit_id)?;
        let unit_id = match (unit_id, segments.first()) {
            (Some(id), _) => id,
            (None, Some(first)) => first.get().segment.labels.unit_id.clone(),
            (None, None) => {
                return Err(
                    Error::Input("`unit_id` must be given when `segments` is empty".into()).into(),
                )
            }
        };
        let sample_rate_hz = segments
            .first()
            .map_or(1000, |s| s.get().segment.sample_rate_hz);
        let mut previous_off_ns: Option<(usize, u64)> = None;
        for (i, segment) in segments.iter().enumerate() {
            let s = &segment.get().segment;
            if s.labels.unit_id != unit_id {
                return Err(Error::Input(format!(
                    "segments[{i}] is of unit {:?}, the recording's is {unit_id:?}",
                    s.labels.unit_id
                ))
                .into());
            }
            if s.sample_rate_hz != sample_rate_hz {
                return Err(Error::Input(format!(
                    "segments[{i}] is sampled at {} Hz, segments[0] at {sample_rate_hz} Hz",
                    s.sample_rate_hz
                ))
                .into());
            }
            if let Some((j, off_ns)) = previous_off_ns {
                if s.power_on_ns <= off_ns {
                    return Err(Error::Input(format!(
                        "segments[{i}] switches on at {} ns, not after segments[{j}] switched off ({off_ns} ns): set `power_on_ns`",
                        s.power_on_ns
                    ))
                    .into());
                }
            }
            let period_ns = 1_000_000_000 / u64::from(s.sample_rate_hz.max(1));
            previous_off_ns = Some((i, s.power_on_ns + s.len() as u64 * period_ns));
        }
        let segments: Vec<Py<PySegment>> = segments.into_iter().map(Bound::unbind).collect();
        let mut all = default_metadata(&unit_id, sample_rate_hz, &segments, py);
        if let Some(extra) = metadata.filter(|m| !m.is_none()) {
            let extra: BTreeMap<String, String> =
                args::value("metadata", "a dict of str → str", extra)?;
            all.extend(extra);
        }
        all.insert("unit_id".into(), unit_id.clone());
        all.insert("sample_rate_hz".into(), sample_rate_hz.to_string());
        Ok(Self {
            path: None,
            metadata: all,
            unit_id,
            sample_rate_hz,
            segments,
        })
    }

    /// A recording from a pandas DataFrame of a continuous log (one or several power-ons):
    /// `gyrodrift.frames.from_dataframe`, documented in the stub and the README.
    #[staticmethod]
    #[pyo3(signature = (frame, **options))]
    fn from_dataframe<'py>(
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        py.import("gyrodrift.frames")?
            .getattr("from_dataframe")?
            .call((frame,), options)
    }

    /// A recording from a CSV file (through pandas): `gyrodrift.frames.read_csv`.
    #[staticmethod]
    #[pyo3(signature = (path, **options))]
    fn read_csv<'py>(
        py: Python<'py>,
        path: &Bound<'py, PyAny>,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        py.import("gyrodrift.frames")?
            .getattr("read_csv")?
            .call((path,), options)
    }

    /// Reads and validates an MCAP recording. Raises `FileError` (missing or unreadable) or
    /// `RecordingError` (naming file, topic and message index).
    #[staticmethod]
    fn load(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Self> {
        load(py, args::path("path", path)?)
    }

    /// A recording's metadata record without decoding its messages.
    #[staticmethod]
    fn read_metadata(
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
    ) -> PyResult<BTreeMap<String, String>> {
        let path = args::path("path", path)?;
        Ok(py.detach(|| read_metadata(&path)).map_err(Error::from)?)
    }

    /// Writes the recording as MCAP (temporary file, then rename); returns the bytes written.
    /// Every segment needs the format's auxiliary channels (accel_x/y/z, supply_voltage,
    /// chamber_set_point at 100 Hz); any other channel is written as a named one (`/aux/<name>`).
    fn save(&self, py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<u64> {
        let path = args::path("path", path)?;
        let arcs = self.segment_arcs(py);
        let metadata = self.metadata.clone();
        let (unit_id, sample_rate_hz) = (self.unit_id.clone(), self.sample_rate_hz);
        let written = py.detach(|| {
            let recording = Recording {
                path: path.clone(),
                metadata,
                unit_id,
                sample_rate_hz,
                segments: arcs.iter().map(|s| (**s).clone()).collect(),
            };
            check_writable(&recording)?;
            write_recording(&recording, &path).map_err(Error::from)
        })?;
        Ok(written)
    }

    /// The file it was read from (None if built in Python).
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// Unit id.
    #[getter]
    fn unit_id(&self) -> &str {
        &self.unit_id
    }

    /// Gyro and temperature sample rate, Hz.
    #[getter]
    fn sample_rate_hz(&self) -> u32 {
        self.sample_rate_hz
    }

    /// The `gyrodrift.recording` metadata record (a new dict on each access).
    #[getter]
    fn metadata(&self) -> BTreeMap<String, String> {
        self.metadata.clone()
    }

    /// The activations, in recording order (a new list of the same Segment objects).
    #[getter]
    fn segments<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.segments.iter().map(|s| s.clone_ref(py)))
    }

    fn __len__(&self) -> usize {
        self.segments.len()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let samples: usize = self
            .segments
            .iter()
            .map(|s| s.bind(py).get().segment.len())
            .sum();
        format!(
            "<Recording {} of {}: {} segments, {samples} samples at {} Hz>",
            self.path
                .as_ref()
                .map_or_else(|| "(in memory)".to_owned(), |p| p.display().to_string()),
            self.unit_id,
            self.segments.len(),
            self.sample_rate_hz
        )
    }
}

/// Every recording of a campaign folder (its `recordings/`) or of a folder of `.mcap` files,
/// sorted by name; ground truth is never opened. Ctrl-C stops it between activations.
#[pyfunction]
pub fn load_campaign(py: Python<'_>, folder: &Bound<'_, PyAny>) -> PyResult<Vec<PyRecording>> {
    let folder = args::path("folder", folder)?;
    let files = recording_files(&folder).map_err(Error::from)?;
    files
        .into_iter()
        .map(|path| {
            // Between files too: each is read in less time than Ctrl-C is looked for.
            py.check_signals()?;
            load(py, path)
        })
        .collect()
}
