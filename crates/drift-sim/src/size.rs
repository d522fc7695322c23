//! What a campaign would write, known before anything is planned in full or allocated: a campaign
//! of a hundred thousand units is refused with its size, not by the allocator.

use crate::campaign::{Campaign, TruthBias};
use crate::schedule;

/// Most a campaign may write unless asked for more, GB.
pub const DEFAULT_MAX_GB: f64 = 20.0;

/// Units planned to extrapolate a large campaign's size from: each unit's schedule is drawn on
/// its own, so the first units are a sample of all of them.
const SAMPLED_UNITS: u32 = 16;

/// Bytes a campaign writes, estimated from its gyro samples: measured 11.5 B per sample of
/// recording, 17.0 B of truth sidecar at every sample and 6.1 B at the auxiliary rate
/// (`gyrodrift simulate --units 1 --set-points 30 --repeats 1 --seed 1`, with and without
/// `--truth-at-aux-rate`: 48.5 MB + 71.5 or 25.6 MB for 4.2 M samples), rounded up.
pub fn estimate_bytes(campaign: &Campaign, samples: u64) -> f64 {
    let truth = match campaign.truth_bias {
        TruthBias::EverySample => 17.5,
        TruthBias::AuxRate => 6.5,
    };
    samples as f64 * (12.0 + truth)
}

/// A size in GB as people read it: `850 MB`, `2.50 GB`, `33.000 TB`.
pub fn gigabytes(gb: f64) -> String {
    if gb >= 1000.0 {
        format!("{:.3} TB", gb / 1000.0)
    } else if gb >= 1.0 {
        format!("{gb:.2} GB")
    } else {
        format!("{:.0} MB", gb * 1000.0)
    }
}

/// A campaign too large for the limit.
#[derive(Debug, thiserror::Error)]
#[error("campaign `{name}` would write about {} (about {samples} samples over {units} units): above {flag} {max_gb}; simulate fewer units, set points or repeats, or raise {flag}", gigabytes(*estimate_gb))]
pub struct TooLarge {
    /// The campaign's name.
    pub name: String,
    /// Its gyro samples (extrapolated from the first units when it has many).
    pub samples: u64,
    /// Its units.
    pub units: u32,
    /// What it would write, GB.
    pub estimate_gb: f64,
    /// The limit, GB.
    pub max_gb: f64,
    /// How to raise the limit (`--max-gb`, `max_gb=`).
    pub flag: &'static str,
}

/// The campaign's gyro samples, if it writes at most `max_gb`: a campaign of many units is first
/// sized from its first units, so one far too large is refused before its full schedule is
/// planned.
pub fn within(c: &Campaign, max_gb: f64, flag: &'static str) -> Result<u64, TooLarge> {
    let refuse = |samples: u64, estimate_gb: f64| TooLarge {
        name: c.name.clone(),
        samples,
        units: c.units,
        estimate_gb,
        max_gb,
        flag,
    };
    if c.units > SAMPLED_UNITS {
        let sample = Campaign {
            units: SAMPLED_UNITS,
            ..c.clone()
        };
        let per_unit = schedule::plan(&sample)
            .iter()
            .map(schedule::FilePlan::samples)
            .sum::<u64>() as f64
            / f64::from(SAMPLED_UNITS);
        let samples = per_unit * f64::from(c.units);
        let estimate_gb = estimate_bytes(c, samples as u64) / 1e9;
        // Units differ only a little (field sessions are drawn): refuse only what is clearly over.
        if estimate_gb > 1.5 * max_gb {
            return Err(refuse(samples as u64, estimate_gb));
        }
    }
    let samples = crate::simulate::total_samples(c);
    let estimate_gb = estimate_bytes(c, samples) / 1e9;
    if estimate_gb > max_gb {
        return Err(refuse(samples, estimate_gb));
    }
    Ok(samples)
}
