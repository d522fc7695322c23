//! The model classes: `gyrodrift.ModifiedTables` (the paper's method),
//! `gyrodrift.PolynomialTables` (the standard and 3rd-order baselines) and
//! `gyrodrift.RelativePolynomialTables` (the baseline relative to the switch-on) and
//! `gyrodrift.RecommendedTables` (the paper's drift with a turn-on bias fitted across activations).
//!
//! All are immutable, validated on construction, and share one API (generated below so it cannot
//! drift apart): JSON and firmware-image conversion, files, settings. `ModifiedTables` adds the
//! extended model's extra terms (`extension`, `with_extension`).

use std::sync::Arc;

use drift_core::{
    Extension, Model, ModifiedTables, PolynomialTables, RecommendedTables,
    RelativePolynomialTables, SwitchOnRate, MAX_TERMS,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyString, PyTuple};

use crate::args;
use crate::errors::Error;
use crate::extension::PyExtraTerm;
use crate::model_io;
use crate::settings::PySettings;

/// One line describing a model's size, for `repr`.
trait Summary {
    fn summary(&self) -> String;
}

impl Summary for ModifiedTables {
    fn summary(&self) -> String {
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|axis| {
                let curves = axis.ambients.first().map_or(0, |a| a.curves.len());
                format!(
                    "{}x{}x{}",
                    axis.reference_ms.len(),
                    axis.ambients.len(),
                    curves
                )
            })
            .collect();
        let terms = match self.extension.terms.len() {
            0 => String::new(),
            1 => "; 1 extra term".to_owned(),
            n => format!("; {n} extra terms"),
        };
        format!(
            "reference times x ambients x curves per axis: {}{terms}",
            axes.join(", ")
        )
    }
}

impl Summary for PolynomialTables {
    fn summary(&self) -> String {
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|axis| {
                let [low, high] = axis.range_celsius;
                format!(
                    "{} coefficients over [{low:?}, {high:?}] °C",
                    axis.coefficients.len()
                )
            })
            .collect();
        format!("per axis: {}", axes.join("; "))
    }
}

impl Summary for RelativePolynomialTables {
    fn summary(&self) -> String {
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|axis| {
                format!(
                    "drift {} + turn-on {} coefficients",
                    axis.drift.coefficients.len(),
                    axis.turn_on.coefficients.len()
                )
            })
            .collect();
        format!("per axis: {}", axes.join("; "))
    }
}

impl Summary for RecommendedTables {
    fn summary(&self) -> String {
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|axis| {
                let curves = axis.table.ambients.first().map_or(0, |a| a.curves.len());
                format!(
                    "{}x{}x{} + turn-on {} coefficients",
                    axis.table.reference_ms.len(),
                    axis.table.ambients.len(),
                    curves,
                    axis.turn_on.polynomial.coefficients.len()
                )
            })
            .collect();
        format!(
            "reference times x ambients x curves per axis: {}",
            axes.join(", ")
        )
    }
}

/// Defines a frozen model class wrapping `Arc<$model>` with the shared API, plus the model's own
/// `#[pymethods]` given after the doc (pyo3 takes one `#[pymethods]` block per class).
macro_rules! model_class {
    ($class:ident, $model:ty, $name:literal, $doc:literal, { $($methods:tt)* }) => {
        #[doc = $doc]
        #[pyclass(module = "gyrodrift", name = $name, frozen, eq)]
        #[derive(Clone, Debug, PartialEq)]
        pub struct $class(pub Arc<$model>);

        impl $class {
            fn checked(tables: $model) -> Result<Self, Error> {
                tables.validate().map_err(Error::Table)?;
                Ok(Self(Arc::new(tables)))
            }
        }

        #[pymethods]
        impl $class {
            /// Parses drift-core's JSON form and validates it.
            #[staticmethod]
            fn from_json(text: &Bound<'_, PyAny>) -> Result<Self, Error> {
                let text = args::text("text", text)?;
                model_io::from_json::<$model>($name, &text).map(|t| Self(Arc::new(t)))
            }

            /// Decodes a firmware table image and validates it.
            #[staticmethod]
            fn from_image(data: &Bound<'_, PyAny>) -> Result<Self, Error> {
                let data = args::bytes("data", data)?;
                model_io::from_image::<$model>(&data).map(|t| Self(Arc::new(t)))
            }

            /// Reads a JSON file written by `save_json` (or the command line).
            #[staticmethod]
            fn load_json(path: &Bound<'_, PyAny>) -> Result<Self, Error> {
                let path = args::path("path", path)?;
                let text = model_io::read_text(&path)?;
                model_io::from_json::<$model>($name, &text).map(|t| Self(Arc::new(t)))
            }

            /// Reads a firmware table image file written by `save_image`.
            #[staticmethod]
            fn load_image(path: &Bound<'_, PyAny>) -> Result<Self, Error> {
                let path = args::path("path", path)?;
                let bytes = model_io::read(&path)?;
                model_io::from_image::<$model>(&bytes).map(|t| Self(Arc::new(t)))
            }

            /// drift-core's JSON form, pretty-printed.
            fn to_json(&self) -> Result<String, Error> {
                model_io::to_json($name, &*self.0)
            }

            /// The firmware table image.
            fn to_image<'py>(&self, py: Python<'py>) -> Result<Bound<'py, PyBytes>, Error> {
                let bytes = model_io::to_image(&*self.0)?;
                Ok(PyBytes::new(py, &bytes))
            }

            /// Writes the JSON form to `path` (atomically: temporary file, then rename).
            fn save_json(&self, path: &Bound<'_, PyAny>) -> Result<(), Error> {
                let path = args::path("path", path)?;
                let text = model_io::to_json($name, &*self.0)?;
                model_io::write(&path, text.as_bytes())
            }

            /// Writes the firmware table image to `path` (atomically).
            fn save_image(&self, path: &Bound<'_, PyAny>) -> Result<(), Error> {
                let path = args::path("path", path)?;
                let bytes = model_io::to_image(&*self.0)?;
                model_io::write(&path, &bytes)
            }

            /// The settings stored with the tables.
            #[getter]
            fn settings(&self) -> PySettings {
                PySettings(self.0.settings)
            }

            /// The same tables with other settings (validated).
            fn with_settings(&self, settings: &Bound<'_, PyAny>) -> Result<Self, Error> {
                let settings = settings.cast::<PySettings>().map_err(|_| {
                    Error::Input(format!(
                        "`settings` must be a gyrodrift.Settings, got {}",
                        crate::arrays::describe(settings)
                    ))
                })?;
                let mut tables = (*self.0).clone();
                tables.settings = settings.get().0;
                Self::checked(tables)
            }

            fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
                crate::pickle_state::reduce(slf)
            }

            fn __repr__(&self) -> String {
                format!("<{} {}>", $name, self.0.summary())
            }

            /// Is this stored calibration still valid? Corrects every activation of `source`
            /// (one unit's recordings or segments, held static) as the firmware would; one
            /// record per axis against the limits (`gyrodrift check` on the command line; the
            /// defaults are `drift_evaluate::check::Limits::default()`, which a test compares).
            #[pyo3(signature = (source, *, max_drift = 0.005, max_rms = 0.02, min_removed = 0.5, settings = None))]
            fn check<'py>(
                &self,
                py: Python<'py>,
                source: &Bound<'py, PyAny>,
                max_drift: f64,
                max_rms: f64,
                min_removed: f64,
                settings: Option<&Bound<'py, PyAny>>,
            ) -> PyResult<Bound<'py, PyAny>> {
                let limits = crate::check::limits(max_drift, max_rms, min_removed)?;
                crate::check::check(py, &self.0, source, &limits, settings)
            }

            $($methods)*
        }
    };
}

model_class!(
    PyModifiedTables,
    ModifiedTables,
    "ModifiedTables",
    "The paper's correlation tables (`drift_core::ModifiedTables`, host capacities 16 x 12 x 32), \
     with the extended model's extra terms if any.",
    {
        /// The extended model's extra terms (empty for the paper's model).
        #[getter]
        fn extension<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
            PyTuple::new(py, self.0.extension.terms.iter().map(|&t| PyExtraTerm(t)))
        }

        /// Per axis X, Y, Z, the rate at switch-on the rate term's filter starts from
        /// (`drift_core::SwitchOnRate`): `[heating °C/s, cooling_per_second,
        /// cooling_per_second_per_remaining]`, a float32 `(3, 3)` array (zeros: at rest).
        #[getter]
        fn switch_on_rate<'py>(&self, py: Python<'py>) -> Result<Bound<'py, PyArray2<f32>>, Error> {
            let values = self
                .0
                .extension
                .switch_on_rate
                .iter()
                .flat_map(|r| {
                    [
                        r.heating_celsius_per_s,
                        r.cooling_per_second,
                        r.cooling_per_second_per_remaining,
                    ]
                })
                .collect();
            Array2::from_shape_vec((3, 3), values)
                .map(|array| array.into_pyarray(py))
                .map_err(|error| Error::Input(format!("internal: rate shape (3, 3): {error}")))
        }

        /// The same tables with `terms` as the extra terms (replacing any; empty: none) and, if
        /// given, `switch_on_rate` (`(3, 3)`; `None` keeps the current one), validated by
        /// drift-core (`TableError` names the term or the axis).
        #[pyo3(signature = (terms, switch_on_rate = None))]
        fn with_extension(
            &self,
            terms: &Bound<'_, PyAny>,
            switch_on_rate: Option<&Bound<'_, PyAny>>,
        ) -> Result<Self, Error> {
            let wrong = || {
                Error::Input(format!(
                    "`terms` must be a sequence of gyrodrift.ExtraTerm, got {}",
                    crate::arrays::describe(terms)
                ))
            };
            if terms.is_instance_of::<PyString>() {
                return Err(wrong());
            }
            let items: Vec<Bound<'_, PyAny>> = terms.extract().map_err(|_| wrong())?;
            if items.len() > MAX_TERMS {
                return Err(Error::Input(format!(
                    "`terms` must hold at most {MAX_TERMS} terms, got {}",
                    items.len()
                )));
            }
            let mut extension = Extension {
                switch_on_rate: self.0.extension.switch_on_rate,
                ..Extension::NONE
            };
            if let Some(value) = switch_on_rate {
                let rows = crate::arrays::rows_per_axis(
                    "switch_on_rate",
                    "a float32 or float64 array of shape (3, 3): per axis X, Y, Z, [heating °C/s, \
                     cooling_per_second, cooling_per_second_per_remaining]",
                    value,
                )?;
                #[allow(clippy::cast_possible_truncation)]
                let rates = rows.map(|[heating, cooling, faster]| SwitchOnRate {
                    heating_celsius_per_s: heating as f32,
                    cooling_per_second: cooling as f32,
                    cooling_per_second_per_remaining: faster as f32,
                });
                extension.switch_on_rate = rates;
            }
            for (index, item) in items.iter().enumerate() {
                let term = item.cast::<PyExtraTerm>().map_err(|_| {
                    Error::Input(format!(
                        "`terms[{index}]` must be a gyrodrift.ExtraTerm, got {}",
                        crate::arrays::describe(item)
                    ))
                })?;
                extension.terms.push(term.get().0).map_err(|_| {
                    Error::Input(format!("`terms` must hold at most {MAX_TERMS} terms"))
                })?;
            }
            let tables = (*self.0)
                .clone()
                .with_extension(extension)
                .map_err(Error::Table)?;
            Ok(Self(Arc::new(tables)))
        }
    }
);

model_class!(
    PyPolynomialTables,
    PolynomialTables,
    "PolynomialTables",
    "A polynomial baseline, standard or 3rd order (`drift_core::PolynomialTables`).",
    {}
);

model_class!(
    PyRelativePolynomialTables,
    RelativePolynomialTables,
    "RelativePolynomialTables",
    "The least-squares baseline relative to the switch-on, bias = q(T_on) + p(T) − p(T_on) \
     (`drift_core::RelativePolynomialTables`).",
    {}
);

model_class!(
    PyRecommendedTables,
    RecommendedTables,
    "RecommendedTables",
    "The recommended model: the paper's drift correction after switch-on with the turn-on bias \
     q(T_on) + h · residual heat fitted across every calibration activation \
     (`drift_core::RecommendedTables`, host capacities 16 x 12 x 32). Start it with \
     `Corrector.power_on_after` to use the residual heat.",
    {}
);
