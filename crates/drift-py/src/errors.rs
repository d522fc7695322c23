//! The Python exception hierarchy and the one conversion from binding errors to Python exceptions.
//!
//! ```text
//! GyrodriftError(Exception)
//! ├── InputError(GyrodriftError, ValueError)   a bad argument: type, dtype, shape, length, value
//! ├── TableError(GyrodriftError)               table JSON or settings that do not form a valid model
//! ├── ImageError(GyrodriftError)               a firmware table image that does not decode
//! └── FileError(GyrodriftError, OSError)       a file that cannot be read or written
//! ```
//!
//! `InputError` and `FileError` also derive from the built-in exception a Python user would catch
//! for that situation, so `except ValueError` / `except OSError` keep working.

use std::path::PathBuf;

use drift_core::blob::BlobError;
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

const INPUT_ERROR_DOC: &str =
    "A bad argument: wrong type, dtype, shape or length, or a value the corrector rejects. Also a ValueError.";
const FILE_ERROR_DOC: &str =
    "A file that cannot be read or written. Also an OSError (`errno`, `strerror`, `filename` are set).";

static INPUT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static FILE_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

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
}

impl From<Error> for PyErr {
    fn from(error: Error) -> Self {
        Python::attach(|py| match error {
            Error::Input(message) => match input_error(py) {
                Ok(class) => PyErr::from_type(class, message),
                Err(err) => err,
            },
            Error::Table(source) => TableError::new_err(format!("invalid tables: {source}")),
            Error::Json { model, source } => {
                TableError::new_err(format!("not a valid {model} JSON: {source}"))
            }
            Error::Image(source) => ImageError::new_err(source.to_string()),
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
    Ok(())
}
