//! The corrector's status flags as module constants (`gyrodrift.Flags` builds an `enum.IntFlag`
//! from them in Python).
//!
//! The list comes from `drift_core::Flags::ALL`, so a flag added to drift-core is a module constant
//! here without an edit; `FLAGS` (every `(name, value)` in bit order) lets the Python tests check
//! that `gyrodrift.Flags` names each of them.

use drift_core::Flags;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// Adds each flag drift-core defines as an `int` constant of the module, then `FAULTS` and `FLAGS`.
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    for (flag, name) in Flags::ALL {
        module.add(name, flag.0)?;
    }
    module.add("FAULTS", Flags::FAULTS.0)?;
    let all = PyTuple::new(
        module.py(),
        Flags::ALL.iter().map(|&(flag, name)| (name, flag.0)),
    )?;
    module.add("FLAGS", all)?;
    Ok(())
}
