//! The paper's campaign: the chamber set points its tables are calibrated at and the one they are
//! validated at. Every default of the command line, the Python module and the simulator reads
//! them from here.

/// Set points whose protocol activations the paper fits, °C.
pub const CALIBRATION_SET_POINTS_CELSIUS: [f64; 2] = [30.0, 40.0];

/// The set point the paper validates at, never fitted, °C.
pub const VALIDATION_SET_POINT_CELSIUS: f64 = 33.0;

/// Every set point of the paper's campaign, in the order it is recorded, °C.
pub const CAMPAIGN_SET_POINTS_CELSIUS: [f64; 3] = [
    CALIBRATION_SET_POINTS_CELSIUS[0],
    CALIBRATION_SET_POINTS_CELSIUS[1],
    VALIDATION_SET_POINT_CELSIUS,
];
