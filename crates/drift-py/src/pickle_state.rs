//! What a class needs to pickle: the `Pickled` trait, `__reduce__`'s tuple and the state codec.
//! A leaf module (it names no class), so the classes and `pickling`'s dispatch do not import each
//! other.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use pyo3::PyClass;
use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::errors::Error;

/// A class that pickles: its kind (the name `_restore` dispatches on) and its state bytes.
pub trait Pickled: PyClass {
    /// The class's Python name.
    const KIND: &'static str;
    /// The state `restore` rebuilds the object from.
    fn state(&self, py: Python<'_>) -> PyResult<Vec<u8>>;
    /// The object rebuilt from `state`.
    fn restore(py: Python<'_>, state: &[u8]) -> PyResult<Self>;
}

/// `__reduce__`: `(gyrodrift._gyrodrift._restore, (kind, version, state))`.
pub fn reduce<'py, T: Pickled>(object: &Bound<'py, T>) -> PyResult<Bound<'py, PyTuple>> {
    let py = object.py();
    let restore = py.import("gyrodrift._gyrodrift")?.getattr("_restore")?;
    let state = PyBytes::new(py, &object.borrow().state(py)?);
    let args = (T::KIND, env!("CARGO_PKG_VERSION"), state).into_pyobject(py)?;
    PyTuple::new(py, [restore, args.into_any()])
}

/// The postcard bytes of `value`.
pub fn encode<T: Serialize>(kind: &str, value: &T) -> PyResult<Vec<u8>> {
    postcard::to_stdvec(value)
        .map_err(|e| Error::Input(format!("internal: pickling {kind}: {e}")).into())
}

/// `value` back from its postcard bytes.
pub fn decode<T: DeserializeOwned>(kind: &str, state: &[u8]) -> PyResult<T> {
    postcard::from_bytes(state)
        .map_err(|e| Error::Input(format!("cannot unpickle {kind}: corrupt state ({e})")).into())
}
