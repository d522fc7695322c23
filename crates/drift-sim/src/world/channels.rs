//! The named auxiliary channels every world records, whatever its effects, and their references.

/// The named channel of the chamber air's relative humidity (%RH).
pub const HUMIDITY: &str = "humidity";
/// Its reference (%RH): effects read the deviation from it.
pub const HUMIDITY_REFERENCE: f64 = 40.0;
/// The named channel of the barometric pressure (hPa).
pub const AIR_PRESSURE: &str = "air_pressure";
/// Its reference (hPa).
pub const AIR_PRESSURE_REFERENCE: f64 = 1013.25;
