//! Where things sit in a campaign folder, and the fixed rates of the format.

/// Folder of a campaign holding the recordings (what fitting and diagnosis read).
pub const RECORDINGS_DIR: &str = "recordings";
/// Folder of a campaign holding simulator ground truth (never read by fitting or diagnosis).
pub const TRUTH_DIR: &str = "truth";
/// File a simulation writes last, in the campaign folder: a folder with [`TRUTH_DIR`] but
/// without it is a simulation that stopped part-way (interrupted, or failed), which no reader
/// accepts.
pub const COMPLETION_MARKER: &str = "summary.json";
/// File-name ending of ground-truth sidecars.
pub const TRUTH_EXTENSION: &str = "truth.mcap";
/// Rate of the auxiliary channels (accelerometer, supply voltage, chamber set point, named
/// channels), Hz.
pub const AUX_RATE_HZ: u32 = 100;

/// Gyro samples per auxiliary sample: auxiliary sample `j` sits beside gyro sample `j · every`.
pub(crate) fn aux_every(sample_rate_hz: u32) -> usize {
    (sample_rate_hz / AUX_RATE_HZ).max(1) as usize
}

/// How many auxiliary samples an activation of `n` samples at `sample_rate_hz` holds at most (one
/// beside every [`aux_every`]-th sample): the writer and the reader share this bound, so what one
/// accepts the other does too.
pub(crate) fn aux_samples_covered(n: usize, sample_rate_hz: u32) -> usize {
    n.div_ceil(aux_every(sample_rate_hz))
}
