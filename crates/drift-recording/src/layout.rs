//! Where things sit in a campaign folder, and the fixed rates of the format.

/// Folder of a campaign holding the recordings (what fitting and diagnosis read).
pub const RECORDINGS_DIR: &str = "recordings";
/// Folder of a campaign holding simulator ground truth (never read by fitting or diagnosis).
pub const TRUTH_DIR: &str = "truth";
/// File-name ending of ground-truth sidecars.
pub const TRUTH_EXTENSION: &str = "truth.mcap";
/// Rate of the auxiliary channels (accelerometer, supply voltage, chamber set point), Hz.
pub const AUX_RATE_HZ: u32 = 100;
