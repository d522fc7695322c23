//! `gyrodrift.ExtraTerm`: one extra linear term of the extended model (`drift_core::ExtraTerm`), as
//! `ModifiedTables.extension` lists them and `ModifiedTables.with_extension` takes them.
//!
//! The class only converts: whether a term is valid (input and axis indices, time constant, finite
//! numbers) is drift-core's `Extension::validate`, run when the term becomes part of a model.

use drift_core::{ExtraTerm, Term};
use pyo3::prelude::*;

use crate::args;
use crate::errors::Error;

/// The kinds' Python names, in `drift_core::Term`'s order.
const KINDS: [&str; 5] = [
    "temperature_rate",
    "aux",
    "axis_rise",
    "rise_squared",
    "aux_times_rise",
];

/// One extra term: kind and parameter (`drift_core::Term`), per-axis centre and coefficient.
#[pyclass(module = "gyrodrift", name = "ExtraTerm", frozen, eq)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PyExtraTerm(pub ExtraTerm);

/// A kind's parameter, read from Python: `what` says what it is, for the error messages.
fn required<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
    kind: &str,
    what: &str,
    expected: &str,
    parameter: Option<&Bound<'py, PyAny>>,
) -> Result<T, Error> {
    match parameter {
        Some(value) if !value.is_none() => args::value("parameter", expected, value),
        _ => Err(Error::Input(format!(
            "`parameter` is required for kind '{kind}' ({what}), got None"
        ))),
    }
}

fn term(
    kind: &str,
    parameter: Option<&Bound<'_, PyAny>>,
    time_constant_ms: Option<&Bound<'_, PyAny>>,
) -> Result<Term, Error> {
    let time_constant_ms = time_constant_ms.filter(|value| !value.is_none());
    if let Some(value) = time_constant_ms.filter(|_| kind != "aux" && kind != "aux_times_rise") {
        return Err(Error::Input(format!(
            "`time_constant_ms` is only for kinds 'aux' and 'aux_times_rise' (a rate term's time constant is its \
             `parameter`), got {} for kind {kind:?}",
            args::shown(value)
        )));
    }
    Ok(match kind {
        "temperature_rate" => Term::TemperatureRate {
            time_constant_ms: required(
                kind,
                "the rate filter's time constant, ms",
                "an integer in 0..=4294967295 (ms)",
                parameter,
            )?,
        },
        "aux" | "aux_times_rise" => {
            let input = required(
                kind,
                "the auxiliary input's index",
                "an integer in 0..=255 (an auxiliary input's index)",
                parameter,
            )?;
            let time_constant_ms = match time_constant_ms {
                Some(value) => args::value(
                    "time_constant_ms",
                    "an integer in 0..=4294967295 (ms)",
                    value,
                )?,
                None => 0,
            };
            if kind == "aux" {
                Term::Aux {
                    input,
                    time_constant_ms,
                }
            } else {
                Term::AuxTimesRise {
                    input,
                    time_constant_ms,
                }
            }
        }
        "axis_rise" => Term::AxisRise {
            axis: required(
                kind,
                "the axis whose rise is read, 0 = X, 1 = Y, 2 = Z",
                "an integer in 0..=255 (an axis index)",
                parameter,
            )?,
        },
        "rise_squared" => {
            if let Some(value) = parameter.filter(|value| !value.is_none()) {
                return Err(Error::Input(format!(
                    "`parameter` must be None for kind 'rise_squared', got {}",
                    args::shown(value)
                )));
            }
            Term::RiseSquared
        }
        other => {
            return Err(Error::Input(format!(
                "`kind` must be one of {}, got {other:?}",
                KINDS.map(|k| format!("'{k}'")).join(", ")
            )))
        }
    })
}

fn kind_name(term: Term) -> &'static str {
    let [rate, aux, axis_rise, rise_squared, aux_times_rise] = KINDS;
    match term {
        Term::TemperatureRate { .. } => rate,
        Term::Aux { .. } => aux,
        Term::AxisRise { .. } => axis_rise,
        Term::RiseSquared => rise_squared,
        Term::AuxTimesRise { .. } => aux_times_rise,
    }
}

fn parameter(term: Term) -> Option<u32> {
    match term {
        Term::TemperatureRate { time_constant_ms } => Some(time_constant_ms),
        Term::Aux { input, .. } | Term::AuxTimesRise { input, .. } => Some(u32::from(input)),
        Term::AxisRise { axis } => Some(u32::from(axis)),
        Term::RiseSquared => None,
    }
}

/// The low-pass time constant of an auxiliary or rate term, ms.
fn time_constant(term: Term) -> Option<u32> {
    match term {
        Term::TemperatureRate { time_constant_ms }
        | Term::Aux {
            time_constant_ms, ..
        }
        | Term::AuxTimesRise {
            time_constant_ms, ..
        } => Some(time_constant_ms),
        Term::AxisRise { .. } | Term::RiseSquared => None,
    }
}

fn triple(values: [f32; 3]) -> (f32, f32, f32) {
    let [x, y, z] = values;
    (x, y, z)
}

#[pymethods]
impl PyExtraTerm {
    /// A term of `kind` with its `parameter` (see the getters), centre and coefficient per axis;
    /// an 'aux' term's low-pass `time_constant_ms` (default 0: unfiltered).
    #[new]
    #[pyo3(signature = (kind, parameter = None, *, centre, coefficient, time_constant_ms = None))]
    fn new(
        kind: &Bound<'_, PyAny>,
        parameter: Option<&Bound<'_, PyAny>>,
        centre: &Bound<'_, PyAny>,
        coefficient: &Bound<'_, PyAny>,
        time_constant_ms: Option<&Bound<'_, PyAny>>,
    ) -> Result<Self, Error> {
        let kind = args::text("kind", kind)?;
        Ok(Self(ExtraTerm {
            term: term(&kind, parameter, time_constant_ms)?,
            centre: args::per_axis("centre", centre)?,
            coefficient: args::per_axis("coefficient", coefficient)?,
        }))
    }

    /// What the term measures: 'temperature_rate', 'aux', 'axis_rise', 'rise_squared' or
    /// 'aux_times_rise'.
    #[getter]
    fn kind(&self) -> &'static str {
        kind_name(self.0.term)
    }

    /// The kind's parameter: the rate filter's time constant (ms), the auxiliary input's index,
    /// the axis whose rise is read; `None` for 'rise_squared'.
    #[getter]
    fn parameter(&self) -> Option<u32> {
        parameter(self.0.term)
    }

    /// The low-pass time constant, ms: an 'aux' or 'aux_times_rise' term's (0: unfiltered), a
    /// 'temperature_rate' term's (its `parameter`); `None` for the other kinds.
    #[getter]
    fn time_constant_ms(&self) -> Option<u32> {
        time_constant(self.0.term)
    }

    /// Per axis, the value the term is measured from (its calibration mean), in the term's unit.
    #[getter]
    fn centre(&self) -> (f32, f32, f32) {
        triple(self.0.centre)
    }

    /// Per axis, °/s per unit of the term.
    #[getter]
    fn coefficient(&self) -> (f32, f32, f32) {
        triple(self.0.coefficient)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        crate::pickle_state::reduce(slf)
    }

    fn __repr__(&self) -> String {
        let parameter = parameter(self.0.term).map_or_else(String::new, |p| format!(", {p}"));
        let filter = match self.0.term {
            Term::Aux {
                time_constant_ms, ..
            } if time_constant_ms != 0 => format!(", time_constant_ms={time_constant_ms}"),
            _ => String::new(),
        };
        format!(
            "ExtraTerm('{}'{parameter}, centre={:?}, coefficient={:?}{filter})",
            kind_name(self.0.term),
            triple(self.0.centre),
            triple(self.0.coefficient)
        )
    }
}

/// Adds the class and drift-core's extension limits (`AUX_INPUTS`, `MAX_EXTRA_TERMS`).
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<PyExtraTerm>()?;
    module.add("AUX_INPUTS", drift_core::AUX_INPUTS)?;
    module.add("MAX_EXTRA_TERMS", drift_core::MAX_TERMS)?;
    Ok(())
}
