//! Simulated campaigns for the `fit` and `read` benches, simulated once in set-up (never timed)
//! into a temporary folder that lives as long as the returned [`Simulated`].
//!
//! Included with `#[path]` by each bench that needs it; not every bench uses every item.
#![allow(dead_code)]

use std::path::PathBuf;

use drift_sim::campaign::TruthBias;
use drift_sim::{simulate_campaign, Campaign};

/// Whether criterion runs in `--test` mode (`cargo bench -- --test`: every bench once, as
/// `scripts/check.sh` does so benches never rot). Benches then use small inputs so the binary
/// finishes in seconds on 2 cores.
pub fn quick() -> bool {
    std::env::args().any(|a| a == "--test")
}

/// The default (paper's) campaign: 2 units, +30/+40 °C calibration and +33 °C validation, the full
/// protocol (7 intervals × 5 activations × 3 repeats × 2 min at 1000 Hz per set point). Ground truth
/// at the 100 Hz auxiliary rate: the fit never reads it, so only set-up time and disk are saved.
pub fn default_campaign() -> Campaign {
    Campaign {
        truth_bias: TruthBias::AuxRate,
        ..Campaign::default()
    }
}

/// A small campaign the fit still accepts (one short interval, one independent, at both
/// calibration set points): 1 unit × 2 set points × 2 intervals × 3 activations × 20 s = 240 000
/// samples. For `--test` mode only.
pub fn small_fit_campaign() -> Campaign {
    let mut c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0, 40.0],
        truth_bias: TruthBias::AuxRate,
        ..Campaign::default()
    };
    if let Some(p) = c.protocol.as_mut() {
        p.intervals_min = vec![1.0, 20.0];
        p.activations = 3;
        p.activation_s = 20.0;
        p.repeats = 1;
    }
    c
}

/// One recording file: 1 unit, +30 °C, intervals 1 and 5 min, 1 repeat = 10 activations × 2 min =
/// 1.2 M samples.
pub fn read_campaign() -> Campaign {
    let mut c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        truth_bias: TruthBias::AuxRate,
        ..Campaign::default()
    };
    if let Some(p) = c.protocol.as_mut() {
        p.intervals_min = vec![1.0, 5.0];
        p.repeats = 1;
    }
    c
}

/// A simulated campaign on disk.
pub struct Simulated {
    /// Keeps the folder alive.
    pub dir: tempfile::TempDir,
    /// The recordings (never the ground truth), sorted by name.
    pub files: Vec<PathBuf>,
}

/// Simulates `campaign` into a new temporary folder.
pub fn simulate(campaign: &Campaign) -> Simulated {
    let dir = tempfile::tempdir().expect("temp dir");
    simulate_campaign(campaign, dir.path(), |_| {}).expect("simulate");
    let files = drift_evaluate::pipeline::recording_files(dir.path()).expect("recordings");
    Simulated { dir, files }
}
