//! The paper's three interpolation stages, one per file, applied in this order per sample:
//! time since switch-on (locate the reference-time segment), heating dynamics (pick the two stored
//! curves whose rises bracket the current rise, within each calibration ambient), and ambient
//! (blend the two calibration ambients that bracket the switch-on temperature; located once at
//! switch-on).

pub mod ambient;
pub mod heating;
pub mod since_power_on;
