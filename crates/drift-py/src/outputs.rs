//! Rust vectors handed to Python as numpy arrays: moved in with `into_pyarray` (no second copy)
//! and marked read-only where the array is a view of data the binding keeps.

use numpy::ndarray::Array2;
use numpy::{Element, IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Marks an array read-only (`arr.flags.writeable == False`), so a cached view cannot drift from
/// the data behind it.
pub fn read_only<'py, T>(array: Bound<'py, T>) -> PyResult<Bound<'py, T>> {
    let py = array.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("write", false)?;
    array.as_any().call_method("setflags", (), Some(&kwargs))?;
    Ok(array)
}

/// Three per-axis vectors as one `(n, 3)` array (interleaved once, then moved into numpy).
pub fn columns<'py, T: Element + Copy>(
    py: Python<'py>,
    axes: &[Vec<T>; 3],
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let n = axes.iter().map(Vec::len).min().unwrap_or(0);
    let mut values = Vec::with_capacity(n.saturating_mul(3));
    for i in 0..n {
        for axis in axes {
            if let Some(v) = axis.get(i) {
                values.push(*v);
            }
        }
    }
    let array = Array2::from_shape_vec((n, 3), values)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("internal: {e}")))?;
    Ok(array.into_pyarray(py))
}

/// A vector as a 1-D array (moved, not copied).
pub fn vector<T: Element>(py: Python<'_>, values: Vec<T>) -> Bound<'_, PyArray1<T>> {
    values.into_pyarray(py)
}
