//! `gyrodrift.excess_cut`: how many times a model cuts the error in excess of the noise floor, with
//! its 95 % bootstrap interval — the figure the closed-loop experiment and `gyrodrift diagnose
//! --extend` give beside each before/after pair ([`drift_fit::excess`]).

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;

use crate::arrays::describe;
use crate::errors::Error;

/// A 1-D float64 or float32 array of finite values, as f64, not empty.
fn values(name: &str, value: &Bound<'_, PyAny>) -> Result<Vec<f64>, Error> {
    let values: Vec<f64> = if let Ok(array) = value.cast::<PyArray1<f64>>() {
        array.to_vec()
    } else if let Ok(array) = value.cast::<PyArray1<f32>>() {
        array
            .to_vec()
            .map(|v| v.into_iter().map(f64::from).collect())
    } else {
        return Err(Error::Input(format!(
            "`{name}` must be a float64 or float32 array of shape (n,), got {}",
            describe(value)
        )));
    }
    .map_err(|e| Error::Input(format!("`{name}` cannot be read: {e}")))?;
    if values.is_empty() {
        return Err(Error::Input(format!("`{name}` has no values")));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::Input(format!(
            "`{name}` must be finite, got {} at index {i}",
            values[i]
        )));
    }
    Ok(values)
}

/// How many times a model cuts the metric's excess over the noise floor,
/// `(mean(before) − mean(floor)) / (mean(after) − mean(floor))`, with the 2.5 and 97.5
/// percentiles of a seeded bootstrap: `before[i]` and `after[i]` are one activation's metric under
/// the two models (resampled together), `floor` the zero-drift twin's activations (resampled
/// apart). Returns `(ratio, low, high)`.
#[pyfunction]
pub fn excess_cut(
    before: &Bound<'_, PyAny>,
    after: &Bound<'_, PyAny>,
    floor: &Bound<'_, PyAny>,
) -> PyResult<(f64, f64, f64)> {
    let (before, after, floor) = (
        values("before", before)?,
        values("after", after)?,
        values("floor", floor)?,
    );
    if before.len() != after.len() {
        return Err(Error::Input(format!(
            "`after` must have one value per activation of `before` ({}), got {}",
            before.len(),
            after.len()
        ))
        .into());
    }
    let cut = drift_fit::excess::excess_cut(&before, &after, &floor);
    Ok((cut.ratio, cut.low, cut.high))
}
