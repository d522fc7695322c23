//! `gyrodrift.excess_cut`: how many times a model cuts the error in excess of the noise floor, with
//! its 95 % bootstrap interval — the figure the closed-loop experiment and `gyrodrift diagnose
//! --extend` give beside each before/after pair ([`drift_evaluate::excess`]).

use pyo3::prelude::*;

use crate::arrays::finite_values_f64;
use crate::errors::Error;

/// [`finite_values_f64`], not empty: a ratio of means needs a mean.
fn values(name: &str, value: &Bound<'_, PyAny>) -> Result<Vec<f64>, Error> {
    let values = finite_values_f64(name, value)?;
    if values.is_empty() {
        return Err(Error::Input(format!("`{name}` has no values")));
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
    let cut = drift_evaluate::excess::excess_cut(&before, &after, &floor);
    Ok((cut.ratio, cut.low, cut.high))
}
