//! The corrector's status flags as module constants (`gyrodrift.Flags` builds an `enum.IntFlag`
//! from them in Python).

use drift_core::Flags;
use pyo3::prelude::*;

/// Every flag drift-core defines, by name, plus the `FAULTS` mask.
pub const FLAGS: [(&str, Flags); 10] = [
    ("AMBIENT_OUT_OF_RANGE", Flags::AMBIENT_OUT_OF_RANGE),
    ("RISE_OUT_OF_SPAN", Flags::RISE_OUT_OF_SPAN),
    ("PAST_LAST_REFERENCE", Flags::PAST_LAST_REFERENCE),
    ("TEMPERATURE_OUT_OF_RANGE", Flags::TEMPERATURE_OUT_OF_RANGE),
    ("TEMPERATURE_INVALID", Flags::TEMPERATURE_INVALID),
    ("TEMPERATURE_STUCK", Flags::TEMPERATURE_STUCK),
    ("RATE_INVALID", Flags::RATE_INVALID),
    ("NOT_POWERED_ON", Flags::NOT_POWERED_ON),
    ("MODEL_INVALID", Flags::MODEL_INVALID),
    ("FAULTS", Flags::FAULTS),
];

/// Adds each flag as an `int` constant of the module.
pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    for (name, flag) in FLAGS {
        module.add(name, flag.0)?;
    }
    Ok(())
}
