//! Python bindings for gyrodrift: the extension module `gyrodrift._gyrodrift`.
//!
//! A thin layer: argument conversion and delegation to drift-core, drift-recording, drift-sim,
//! drift-fit, drift-evaluate and drift-diagnose; the numeric work stays there. One file per Python-facing area; shared argument
//! checks in `args` and `arrays`, numpy outputs in `outputs`; every error goes through `errors`.
//! See `README.md`.

mod analysed;
mod args;
mod arrays;
mod check;
mod corrector;
mod csv_input;
mod diagnosis;
mod errors;
mod evaluation;
mod excess;
mod extension;
mod fit;
mod fit_settings;
mod flags;
mod interrupt;
mod labels;
mod model_io;
mod outputs;
mod pickle_state;
mod pickling;
mod recording;
mod results;
mod segment;
mod settings;
mod simulate;
mod sources;
mod stillness;
mod tables;
mod uncertainty;

use pyo3::prelude::*;

/// The extension module; `python/gyrodrift/__init__.py` re-exports it as `gyrodrift`.
#[pymodule]
fn _gyrodrift(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(module)?;
    flags::register(module)?;
    module.add_class::<settings::PySettings>()?;
    module.add_class::<tables::PyModifiedTables>()?;
    extension::register(module)?;
    module.add_class::<tables::PyPolynomialTables>()?;
    module.add_class::<tables::PyRelativePolynomialTables>()?;
    module.add_class::<tables::PyRecommendedTables>()?;
    module.add_class::<corrector::PyCorrector>()?;
    module.add_class::<corrector::PyOutput>()?;
    module.add_class::<stillness::PyStillnessLearner>()?;
    module.add_class::<uncertainty::PyUncertainty>()?;
    module.add_class::<labels::PyLabels>()?;
    module.add_class::<segment::PyAuxChannel>()?;
    module.add_class::<segment::PySegment>()?;
    module.add_class::<recording::PyRecording>()?;
    module.add_function(wrap_pyfunction!(recording::load_campaign, module)?)?;
    module.add_function(wrap_pyfunction!(simulate::simulate, module)?)?;
    module.add_function(wrap_pyfunction!(simulate::resolve_campaign, module)?)?;
    module.add_class::<fit_settings::PyFitSettings>()?;
    module.add_class::<fit::PyFittedUnit>()?;
    module.add_class::<diagnosis::PyDiagnosis>()?;
    module.add_function(wrap_pyfunction!(fit::fit, module)?)?;
    module.add_class::<analysed::PyAnalysed>()?;
    module.add_function(wrap_pyfunction!(analysed::analyse, module)?)?;
    module.add_class::<results::PyActivationResult>()?;
    module.add_class::<evaluation::PyEvaluation>()?;
    module.add_function(wrap_pyfunction!(evaluation::evaluate, module)?)?;
    module.add_function(wrap_pyfunction!(evaluation::summarise, module)?)?;
    module.add_function(wrap_pyfunction!(evaluation::report, module)?)?;
    module.add_function(wrap_pyfunction!(excess::excess_cut, module)?)?;
    module.add_function(wrap_pyfunction!(pickling::restore, module)?)?;
    module.add_function(wrap_pyfunction!(csv_input::read_csv_text, module)?)?;
    Ok(())
}
