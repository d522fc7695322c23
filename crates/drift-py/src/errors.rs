//! The Python exception hierarchy and the one conversion from binding errors to Python exceptions.
//!
//! ```text
//! GyrodriftError(Exception)
//! ├── InputError(GyrodriftError, ValueError)   a bad argument: type, dtype, shape, length, value
//! ├── TableError(GyrodriftError)               table JSON or settings that do not form a valid model
//! ├── ImageError(GyrodriftError)               a firmware table image that does not decode
//! ├── FileError(GyrodriftError, OSError)       a file that cannot be read or written
//! ├── RecordingError(GyrodriftError)           a recording that does not read, validate or write
//! ├── CampaignError(GyrodriftError, ValueError) a simulation campaign that is not valid
//! └── FitError(GyrodriftError)                 data the tables cannot be fitted or evaluated from
//! ```
//!
//! `InputError` and `FileError` also derive from the built-in exception a Python user would catch
//! for that situation, so `except ValueError` / `except OSError` keep working.

use std::path::PathBuf;

use drift_core::blob::BlobError;
use drift_evaluate::pipeline::PipelineError;
use drift_evaluate::tables_folder::TablesError;
use drift_fit::FitError as RustFitError;
use drift_recording::{ReadError, WriteError};
use drift_sim::SimError;
use pyo3::exceptions::{PyException, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

pyo3::create_exception!(
    gyrodrift,
    GyrodriftError,
    PyException,
    "Base class of every error gyrodrift raises."
);
pyo3::create_exception!(
    gyrodrift,
    TableError,
    GyrodriftError,
    "Table JSON or settings that do not form a valid model; the message names the field and where it sits."
);
pyo3::create_exception!(
    gyrodrift,
    ImageError,
    GyrodriftError,
    "A firmware table image that cannot be decoded (bad magic, version, kind, length, CRC, payload or contents)."
);

pyo3::create_exception!(
    gyrodrift,
    RecordingError,
    GyrodriftError,
    "A recording that cannot be read, fails validation or cannot be written; the message names the file, and the topic and message index where it applies."
);
pyo3::create_exception!(
    gyrodrift,
    FitError,
    GyrodriftError,
    "Recordings the tables cannot be fitted or evaluated from; the message names the unit and activation, or the setting."
);

const CAMPAIGN_ERROR_DOC: &str =
    "A simulation campaign that is not valid (unknown field, value out of range, unparsable text). Also a ValueError.";
const INPUT_ERROR_DOC: &str =
    "A bad argument: wrong type, dtype, shape or length, or a value the corrector rejects. Also a ValueError.";
const FILE_ERROR_DOC: &str =
    "A file that cannot be read or written. Also an OSError (`errno`, `strerror`, `filename` are set).";

static INPUT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static FILE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static CAMPAIGN_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A class of the hierarchy with two bases, made once per interpreter by calling `type(...)`
/// (`create_exception!` takes a single base).
fn two_base_class<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyType>>,
    name: &str,
    builtin: Bound<'py, PyType>,
    doc: &str,
) -> PyResult<Bound<'py, PyType>> {
    let class = cell.get_or_try_init(py, || {
        let bases = PyTuple::new(py, [py.get_type::<GyrodriftError>(), builtin])?;
        let namespace = PyDict::new(py);
        namespace.set_item("__module__", "gyrodrift")?;
        namespace.set_item("__doc__", doc)?;
        let class = py.get_type::<PyType>().call1((name, bases, namespace))?;
        Ok::<_, PyErr>(class.cast_into::<PyType>()?.unbind())
    })?;
    Ok(class.bind(py).clone())
}

/// `gyrodrift.InputError`.
pub fn input_error(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    two_base_class(
        py,
        &INPUT_ERROR,
        "InputError",
        py.get_type::<PyValueError>(),
        INPUT_ERROR_DOC,
    )
}

/// `gyrodrift.FileError`.
pub fn file_error(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    two_base_class(
        py,
        &FILE_ERROR,
        "FileError",
        py.get_type::<PyOSError>(),
        FILE_ERROR_DOC,
    )
}

/// `gyrodrift.CampaignError`.
pub fn campaign_error(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    two_base_class(
        py,
        &CAMPAIGN_ERROR,
        "CampaignError",
        py.get_type::<PyValueError>(),
        CAMPAIGN_ERROR_DOC,
    )
}

/// Everything the binding can fail with. Converted to a Python exception in one place
/// (`From<Error> for PyErr`), so every message and class is decided here.
#[derive(Debug)]
pub enum Error {
    /// A bad argument; the message names the argument, what was expected and what arrived.
    Input(String),
    /// Tables or settings failed drift-core's validation.
    Table(drift_core::Error),
    /// Text that is not the JSON of the named model type.
    Json {
        /// Python name of the model type asked for.
        model: &'static str,
        /// serde_json's error (has line and column).
        source: serde_json::Error,
    },
    /// A firmware table image that does not decode.
    Image(BlobError),
    /// A file that cannot be read or written.
    File {
        /// What was being done: "read" or "write".
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A recording that does not read or validate (the text names file, topic, message index).
    Read(ReadError),
    /// A recording that cannot be written.
    Write(WriteError),
    /// A campaign that is not valid, or a simulation that failed.
    Simulate(SimError),
    /// A campaign given as text or a dict that does not parse.
    Campaign(String),
    /// Fitting or evaluation failed.
    Fit(RustFitError),
    /// The fit/evaluate pipeline stopped.
    Pipeline(PipelineError),
    /// The report could not be made (the message names the step and the file).
    Report(String),
}

impl From<drift_recording::Interrupted> for Error {
    /// Never shown: the exception that stopped the work (`interrupt::run`) is raised instead.
    fn from(_: drift_recording::Interrupted) -> Self {
        Error::Input("interrupted".into())
    }
}

impl From<ReadError> for Error {
    fn from(error: ReadError) -> Self {
        match error {
            ReadError::Io { path, source } => Self::File {
                action: "read",
                path,
                source,
            },
            other => Self::Read(other),
        }
    }
}

impl From<WriteError> for Error {
    fn from(error: WriteError) -> Self {
        match error {
            WriteError::Io { path, source } => Self::File {
                action: "write",
                path,
                source,
            },
            other => Self::Write(other),
        }
    }
}

impl From<SimError> for Error {
    fn from(error: SimError) -> Self {
        match error {
            SimError::Io { path, source } => Self::File {
                action: "write",
                path,
                source,
            },
            SimError::Write(error) => error.into(),
            other => Self::Simulate(other),
        }
    }
}

impl From<TablesError> for Error {
    fn from(error: TablesError) -> Self {
        match error {
            TablesError::Io {
                action,
                path,
                problem,
            } => Self::File {
                action,
                path,
                source: problem,
            },
            TablesError::Encode { problem, .. } | TablesError::Decode { problem, .. } => {
                Self::Image(problem)
            }
            TablesError::Json { problem, .. } => Self::Json {
                model: "tables",
                source: problem,
            },
            section @ TablesError::Section { .. } => Self::Input(section.to_string()),
        }
    }
}

impl From<RustFitError> for Error {
    fn from(error: RustFitError) -> Self {
        Self::Fit(error)
    }
}

impl From<PipelineError> for Error {
    fn from(error: PipelineError) -> Self {
        match error {
            PipelineError::List { path, source } => Self::File {
                action: "read",
                path,
                source,
            },
            PipelineError::Read(error) => error.into(),
            PipelineError::Fit(error) => Self::Fit(error),
            other => Self::Pipeline(other),
        }
    }
}

/// An instance of a two-base class, or the error of making the class.
fn two_base_error(class: PyResult<Bound<'_, PyType>>, message: String) -> PyErr {
    match class {
        Ok(class) => PyErr::from_type(class, message),
        Err(err) => err,
    }
}

impl From<Error> for PyErr {
    fn from(error: Error) -> Self {
        Python::attach(|py| match error {
            Error::Input(message) => two_base_error(input_error(py), message),
            Error::Table(source) => TableError::new_err(format!("invalid tables: {source}")),
            Error::Json { model, source } => {
                TableError::new_err(format!("not a valid {model} JSON: {source}"))
            }
            Error::Image(source) => {
                ImageError::new_err(drift_evaluate::tables_folder::blob_message(&source))
            }
            Error::File {
                action,
                path,
                source,
            } => {
                let strerror = format!("cannot {action} file: {source}");
                let filename = path.to_string_lossy().into_owned();
                match (file_error(py), source.raw_os_error()) {
                    (Ok(class), Some(errno)) => {
                        PyErr::from_type(class, (errno, strerror, filename))
                    }
                    (Ok(class), None) => PyErr::from_type(class, format!("{strerror}: {filename}")),
                    (Err(err), _) => err,
                }
            }
            Error::Read(source) => RecordingError::new_err(source.to_string()),
            Error::Write(source) => {
                RecordingError::new_err(format!("cannot write recording: {source}"))
            }
            Error::Simulate(source @ (SimError::Campaign { .. } | SimError::Parse { .. })) => {
                two_base_error(campaign_error(py), source.to_string())
            }
            Error::Simulate(source) => {
                two_base_error(campaign_error(py), format!("simulation failed: {source}"))
            }
            Error::Campaign(message) => two_base_error(campaign_error(py), message),
            Error::Fit(source) => FitError::new_err(source.to_string()),
            Error::Pipeline(source @ PipelineError::NoRecordings { .. }) => {
                RecordingError::new_err(source.to_string())
            }
            Error::Pipeline(source) => FitError::new_err(source.to_string()),
            Error::Report(message) => FitError::new_err(message),
        })
    }
}

/// Registers the hierarchy in the module.
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add("GyrodriftError", py.get_type::<GyrodriftError>())?;
    module.add("InputError", input_error(py)?)?;
    module.add("TableError", py.get_type::<TableError>())?;
    module.add("ImageError", py.get_type::<ImageError>())?;
    module.add("FileError", file_error(py)?)?;
    module.add("RecordingError", py.get_type::<RecordingError>())?;
    module.add("CampaignError", campaign_error(py)?)?;
    module.add("FitError", py.get_type::<FitError>())?;
    Ok(())
}
