//! The oracle of the worlds benchmark: what an analysis that knows the truth detects on the same
//! data. The world's undeclared effect alone (the simulator's `/truth/hidden_effect_bias`, per
//! axis) joins every activation as a recorded channel (`oracle_x`, `oracle_y`, `oracle_z`), and
//! the loop's own diagnosis — the same fit, baseline, folds, shuffles and size threshold as the
//! blind run — scores it beside the candidates. Its gain on its own axis is what the effect itself
//! explains beyond the baseline: an axis where even the true regressor stays under the detectable
//! share cannot have the effect found by any regressor built from the recordings. The oracle's
//! loop extends the model as the blind one does, so its held-out drift excess cut is what an
//! analysis that knows the truth cuts on the same activations.
//!
//! Run after the blind loop, in a process of its own (it reads the truth).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use drift_diagnose::activations::at_diagnosis_rate;
use drift_evaluate::excess::{excess_cut, ExcessCut};
use drift_fit::FitSettings;
use drift_recording::{read_recording, AuxChannel, Segment, RECORDINGS_DIR, TRUTH_EXTENSION};
use drift_sim::truth::read_truth;
use serde::{Deserialize, Serialize};

use crate::judged::judged_axes;
use crate::memory::peak_rss_mb;
use crate::world_loop::fit_and_close;

/// How a candidate or term built on a truth channel is named.
const ORACLE_TERM: &str = "aux:oracle_";

/// The recorded channel that carries the truth on axis `axis`.
pub fn oracle_channel(axis: usize) -> String {
    format!("oracle_{}", ["x", "y", "z"][axis.min(2)])
}

/// Every activation of every recording in `recordings`, each with the world's effect alone as
/// three channels, read from the sidecar of the same name in `truth`; at the loop's rate
/// ([`drift_diagnose::activations`]), as the blind run's.
pub fn segments_with_oracle(recordings: &Path, truth: &Path) -> anyhow::Result<Vec<Segment>> {
    let mut out = Vec::new();
    for path in drift_evaluate::pipeline::recording_files(recordings)? {
        let stem = path
            .file_stem()
            .context("a recording without a name")?
            .to_string_lossy()
            .into_owned();
        let sidecar = truth.join(format!("{stem}.{TRUTH_EXTENSION}"));
        let truths =
            read_truth(&sidecar).with_context(|| format!("reading {}", sidecar.display()))?;
        let mut segments = read_recording(&path)?.segments;
        anyhow::ensure!(
            truths.len() == segments.len(),
            "{}: {} activations, its truth {}",
            path.display(),
            segments.len(),
            truths.len()
        );
        for (segment, truth) in segments.iter_mut().zip(truths) {
            for (axis, values) in truth.effect_dps.into_iter().enumerate() {
                anyhow::ensure!(
                    !values.is_empty(),
                    "{}: no effect truth (not a drawn world's sidecar)",
                    sidecar.display()
                );
                segment.aux.insert(
                    oracle_channel(axis),
                    AuxChannel {
                        unit: "deg/s".into(),
                        sample_rate_hz: drift_recording::AUX_RATE_HZ,
                        values,
                    },
                );
            }
        }
        out.extend(segments.into_iter().map(at_diagnosis_rate));
    }
    Ok(out)
}

/// What the loop's diagnosis made of the true regressor on one axis.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OracleAxis {
    /// Its gain over the baseline (cross-validated by series; the share of the residual's variance
    /// it explains out of sample).
    pub gain: f64,
    /// The gain a candidate had to exceed on the axis in the oracle's run.
    pub detectable_share: f64,
    /// Its family-wise p-value (shuffles).
    pub family_p_value: f64,
    /// Selected into the baseline by the loop's rule.
    pub selected: bool,
    /// Its rank among the candidates (1: first).
    pub rank: usize,
    /// Share of its variance the paper's tables predict (what they already correct of it).
    pub absorbed_by_model: f64,
    /// Where it shows (within or between activations, or absorbed).
    pub level: String,
    /// Whether the guard admitted a term of the truth (this axis's or another's: a channel's
    /// effect moves every axis alike) into the extended model on the axis.
    pub admitted: bool,
    /// Every term the oracle's loop admitted on the axis (the unit's thermal response included).
    pub terms: Vec<String>,
    /// Terms the oracle's guard left out on the axis, each with its reason.
    pub refused: Vec<String>,
    /// The held-out drift excess cut of the oracle's extended model, as the blind loop's is
    /// measured (the same activations and floor).
    pub cut: ExcessCut,
}

impl OracleAxis {
    /// The true regressor clears the axis's detectable share: some analysis of these data can
    /// find the effect here.
    pub fn detectable(&self) -> bool {
        self.gain > 0.0 && self.gain >= self.detectable_share
    }
}

/// The oracle's run on one world.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OracleOutcome {
    /// Per axis (`None` where the diagnosis had no score for the oracle's channel).
    pub axes: Vec<Option<OracleAxis>>,
    /// Wall time, s.
    pub seconds: f64,
    /// Peak resident memory of the process, MB.
    pub peak_rss_mb: f64,
}

/// The oracle's run: the blind loop (same options, extended model on) on recordings that carry
/// the truth as channels, judged beside the twin in `floor_dir`. `oracle_dir` holds the sidecars
/// of `dir` (`world/`) and of `diagnosis_dir` (`diagnosis/`).
pub fn close_oracle(
    dir: &Path,
    diagnosis_dir: Option<&Path>,
    oracle_dir: &Path,
    floor_dir: &Path,
    settings: &FitSettings,
    select_on_validation: bool,
) -> anyhow::Result<OracleOutcome> {
    let started = Instant::now();
    let all = segments_with_oracle(&dir.join(RECORDINGS_DIR), &oracle_dir.join("world"))?;
    let diagnosis = match diagnosis_dir {
        Some(d) => segments_with_oracle(&d.join(RECORDINGS_DIR), &oracle_dir.join("diagnosis"))?,
        None => Vec::new(),
    };
    let diagnosis: Vec<&Segment> = diagnosis.iter().collect();
    let (base, closed) = fit_and_close(&all, &diagnosis, true, select_on_validation, settings)?;
    let judged = judged_axes(&base, &closed, floor_dir, settings)?;
    let axes = (0..3)
        .map(|a| {
            let d = &closed.axes[a];
            let j = &judged[a];
            let name = format!("aux:{}", oracle_channel(a));
            d.ranking.iter().position(|c| c.name == name).map(|rank| {
                let c = &d.ranking[rank];
                OracleAxis {
                    gain: c.explained,
                    detectable_share: d.detectable_share,
                    family_p_value: c.family_p_value,
                    selected: c.significant,
                    rank: rank + 1,
                    absorbed_by_model: c.absorbed_by_model,
                    level: c.level.to_owned(),
                    admitted: j.admitted.iter().any(|t| t.starts_with(ORACLE_TERM)),
                    terms: j.admitted.clone(),
                    refused: j.refused.clone(),
                    cut: excess_cut(&j.before_dps, &j.after_dps, &j.floor_dps),
                }
            })
        })
        .collect();
    Ok(OracleOutcome {
        axes,
        seconds: started.elapsed().as_secs_f64(),
        peak_rss_mb: peak_rss_mb(),
    })
}
