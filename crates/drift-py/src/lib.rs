//! Python bindings for gyrodrift: the extension module `gyrodrift._gyrodrift`.
//!
//! A thin layer: argument conversion and delegation to drift-core; the numeric work stays there.
//! One file per Python-facing area (`tables`, `settings`, `corrector`, `flags`); shared argument
//! checks in `args` and `arrays`; every error goes through `errors`. See `README.md`.

mod args;
mod arrays;
mod corrector;
mod errors;
mod flags;
mod model_io;
mod settings;
mod tables;

use pyo3::prelude::*;

/// The extension module; `python/gyrodrift/__init__.py` re-exports it as `gyrodrift`.
#[pymodule]
fn _gyrodrift(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(module)?;
    flags::register(module)?;
    module.add_class::<settings::PySettings>()?;
    module.add_class::<tables::PyModifiedTables>()?;
    module.add_class::<tables::PyPolynomialTables>()?;
    module.add_class::<corrector::PyCorrector>()?;
    module.add_class::<corrector::PyOutput>()?;
    Ok(())
}
