//! Plain Python arguments (numbers, sequences, bytes, paths), each checked with a message that names
//! the argument, what was expected and what arrived.

use std::path::PathBuf;

use drift_core::AUX_INPUTS;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes};

use crate::arrays::describe;
use crate::errors::Error;

/// A time since switch-on in ms: an integer in `0 ..= 2**32 - 1`.
pub fn milliseconds(name: &str, value: &Bound<'_, PyAny>) -> Result<u32, Error> {
    value.extract::<u32>().map_err(|_| {
        let got = value
            .repr()
            .map_or_else(|_| describe(value), |repr| repr.to_string());
        Error::Input(format!(
            "`{name}` must be an integer in 0..=4294967295 (ms), got {got}"
        ))
    })
}

/// Three floats, one per axis (X, Y, Z); NaN and infinity are accepted (the corrector flags them).
pub fn per_axis(name: &str, value: &Bound<'_, PyAny>) -> Result<[f32; 3], Error> {
    // f64 first, then rounded to f32 per value (as numpy's astype does): pyo3's f32 extraction would
    // do the same, but reading through f64 keeps the conversion explicit.
    value
        .extract::<[f64; 3]>()
        .map(|values| values.map(|v| v as f32))
        .map_err(|_| {
            Error::Input(format!(
                "`{name}` must be a sequence of 3 floats (X, Y, Z), got {}",
                describe(value)
            ))
        })
}

/// The auxiliary inputs of one sample (`drift_core::AUX_INPUTS` floats, by input index); NaN and
/// infinity are accepted (the corrector holds the terms that read them, flagged).
pub fn aux_inputs(name: &str, value: &Bound<'_, PyAny>) -> Result<[f32; AUX_INPUTS], Error> {
    value
        .extract::<[f64; AUX_INPUTS]>()
        .map(|values| values.map(|v| v as f32))
        .map_err(|_| {
            Error::Input(format!(
                "`{name}` must be a sequence of {AUX_INPUTS} floats (auxiliary inputs 0..{AUX_INPUTS}) \
                 or a float array of shape ({AUX_INPUTS},), got {}",
                describe(value)
            ))
        })
}

/// Bytes or bytearray contents.
pub fn bytes(name: &str, value: &Bound<'_, PyAny>) -> Result<Vec<u8>, Error> {
    if let Ok(bytes) = value.cast::<PyBytes>() {
        Ok(bytes.as_bytes().to_vec())
    } else if let Ok(array) = value.cast::<PyByteArray>() {
        Ok(array.to_vec())
    } else {
        Err(Error::Input(format!(
            "`{name}` must be bytes or bytearray, got {}",
            describe(value)
        )))
    }
}

/// A `str` argument.
pub fn text(name: &str, value: &Bound<'_, PyAny>) -> Result<String, Error> {
    value
        .extract::<String>()
        .map_err(|_| Error::Input(format!("`{name}` must be a str, got {}", describe(value))))
}

/// A filesystem path: `str` or `os.PathLike`.
pub fn path(name: &str, value: &Bound<'_, PyAny>) -> Result<PathBuf, Error> {
    value.extract::<PathBuf>().map_err(|_| {
        Error::Input(format!(
            "`{name}` must be a str or os.PathLike path, got {}",
            describe(value)
        ))
    })
}

/// A finite-or-not float (validation happens where the value is used).
pub fn float(name: &str, value: &Bound<'_, PyAny>) -> Result<f32, Error> {
    value
        .extract::<f64>()
        .map(|v| v as f32)
        .map_err(|_| Error::Input(format!("`{name}` must be a float, got {}", describe(value))))
}

/// A sample count in `0 ..= 65535`.
pub fn count_u16(name: &str, value: &Bound<'_, PyAny>) -> Result<u16, Error> {
    value.extract::<u16>().map_err(|_| {
        let got = value
            .repr()
            .map_or_else(|_| describe(value), |repr| repr.to_string());
        Error::Input(format!(
            "`{name}` must be an integer in 0..=65535, got {got}"
        ))
    })
}

/// An argument as an error message shows it: its repr for plain values, dtype and shape for arrays.
pub fn shown(value: &Bound<'_, PyAny>) -> String {
    if value.cast::<numpy::PyUntypedArray>().is_ok() {
        return describe(value);
    }
    value
        .repr()
        .map_or_else(|_| describe(value), |repr| repr.to_string())
}

/// Any argument pyo3 can convert to `T`; `expected` says what is accepted ("an integer ≥ 1").
pub fn value<'py, T: FromPyObjectOwned<'py>>(
    name: &str,
    expected: &str,
    value: &Bound<'py, PyAny>,
) -> Result<T, Error> {
    value
        .extract::<T>()
        .map_err(|_| Error::Input(format!("`{name}` must be {expected}, got {}", shown(value))))
}

/// An optional argument (`None` or left out: `None`).
pub fn optional<'py, T: FromPyObjectOwned<'py>>(
    name: &str,
    expected: &str,
    argument: Option<&Bound<'py, PyAny>>,
) -> Result<Option<T>, Error> {
    match argument {
        Some(v) if !v.is_none() => value(name, expected, v).map(Some),
        _ => Ok(None),
    }
}
