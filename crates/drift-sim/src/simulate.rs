//! Runs a whole campaign into an output folder.
//!
//! ```text
//! <out>/recordings/GIU-01_sp+30.0C_protocol.mcap      what a test bench would record
//! <out>/truth/GIU-01_sp+30.0C_protocol.truth.mcap     per-sample true bias, node temperatures
//! <out>/truth/units.json                              every unit's drawn parameters
//! <out>/truth/campaign.json                           the full campaign (effects, seed)
//! <out>/summary.json                                  files, samples, bytes (no truth)
//! ```

use crate::campaign::Campaign;
use crate::engine::FileSim;
use crate::error::SimError;
use crate::schedule::{self, FilePlan};
use crate::unit::UnitParams;
use crate::world::runtime::{AuxActivation, Runtime};
use drift_recording::{SeriesKind, COMPLETION_MARKER, RECORDINGS_DIR, TRUTH_DIR, TRUTH_EXTENSION};
use serde::Serialize;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Progress of a running campaign.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Samples simulated so far.
    pub samples_done: u64,
    /// Samples in the whole campaign.
    pub samples_total: u64,
    /// Files finished so far.
    pub files_done: usize,
    /// Files in the campaign.
    pub files_total: usize,
}

/// One written recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileSummary {
    /// The recording (MCAP).
    pub recording: PathBuf,
    /// Its ground-truth sidecar.
    pub truth: PathBuf,
    /// Unit id.
    pub unit_id: String,
    /// Chamber set point (°C).
    pub set_point_celsius: f64,
    /// Series kind.
    pub series_kind: SeriesKind,
    /// Activations recorded.
    pub activations: u64,
    /// Gyro samples recorded (per axis).
    pub samples: u64,
    /// Recording size (bytes).
    pub recording_bytes: u64,
    /// Sidecar size (bytes).
    pub truth_bytes: u64,
}

/// What a campaign run produced.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Campaign name.
    pub campaign: String,
    /// Files, in recording order.
    pub files: Vec<FileSummary>,
    /// Gyro samples in all files.
    pub samples: u64,
    /// Bytes of all recordings (without truth).
    pub recording_bytes: u64,
    /// Bytes of all truth sidecars.
    pub truth_bytes: u64,
    /// Wall time of the run (s).
    pub wall_s: f64,
}

/// Draws the campaign's units.
pub fn draw_units(c: &Campaign) -> Vec<UnitParams> {
    (0..c.units)
        .map(|i| UnitParams::draw(c.seed, i, c.unit_model, &c.effects))
        .collect()
}

/// Samples the campaign will record (for a progress bar's length).
pub fn total_samples(c: &Campaign) -> u64 {
    schedule::plan(c)
        .iter()
        .map(schedule::FilePlan::samples)
        .sum()
}

pub(crate) fn write_json(path: &Path, value: &impl Serialize) -> Result<(), SimError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| SimError::Json {
        path: path.to_path_buf(),
        source: e,
    })?;
    drift_recording::write_atomic(path, text.as_bytes()).map_err(|e| SimError::io(path, e))
}

/// Simulates and records a whole campaign into `out_dir` (created if missing).
///
/// Deterministic: the same campaign gives bit-identical recordings. `progress` is called
/// after every 100-ms batch.
pub fn simulate_campaign(
    c: &Campaign,
    out_dir: &Path,
    mut progress: impl FnMut(Progress),
) -> Result<Summary, SimError> {
    simulate_campaign_until(c, out_dir, |p| {
        progress(p);
        ControlFlow::Continue(())
    })
}

/// [`simulate_campaign`] with a `progress` that may stop the run: called after each block of
/// samples (a tenth of a second of recording), a break ends it with [`SimError::Interrupted`],
/// leaving the files of the run unfinished (a caller writing into a staging folder removes it).
pub fn simulate_campaign_until(
    c: &Campaign,
    out_dir: &Path,
    mut progress: impl FnMut(Progress) -> ControlFlow<()>,
) -> Result<Summary, SimError> {
    c.validate()?;
    let started = Instant::now();
    let plans = schedule::plan(c);
    let units = draw_units(c);
    record(c, &units, &plans, None, out_dir, started, &mut progress)
}

/// [`simulate_campaign_until`] reporting to a [`drift_recording::Progress`]: step
/// [`SIMULATING`], samples done of the campaign's samples.
pub fn simulate_campaign_with(
    c: &Campaign,
    out_dir: &Path,
    progress: &dyn drift_recording::Progress,
) -> Result<Summary, SimError> {
    simulate_campaign_until(c, out_dir, |p| {
        progress.report(SIMULATING, p.samples_done, p.samples_total)
    })
}

/// The step [`simulate_campaign_with`] reports.
pub const SIMULATING: &str = "simulating";

/// A world's part of a run: its runtime, and its named channels per file and activation.
pub(crate) type WorldPart<'a> = (&'a Runtime, &'a [Vec<AuxActivation>]);

/// Records planned files of drawn units (and a world's extras) into `out_dir`.
pub(crate) fn record(
    c: &Campaign,
    units: &[UnitParams],
    plans: &[FilePlan],
    world: Option<WorldPart>,
    out_dir: &Path,
    started: Instant,
    progress: &mut dyn FnMut(Progress) -> ControlFlow<()>,
) -> Result<Summary, SimError> {
    let recordings = out_dir.join(RECORDINGS_DIR);
    let truth = out_dir.join(TRUTH_DIR);
    // The completion marker is written last: a stale one from an earlier run would vouch for a
    // folder this run may leave half-written.
    let marker = out_dir.join(COMPLETION_MARKER);
    match std::fs::remove_file(&marker) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(SimError::io(&marker, e)),
        _ => {}
    }
    for dir in [&recordings, &truth] {
        std::fs::create_dir_all(dir).map_err(|e| SimError::io(dir, e))?;
    }
    write_json(&truth.join("campaign.json"), c)?;
    write_json(&truth.join("units.json"), &units)?;

    let samples_total: u64 = plans.iter().map(schedule::FilePlan::samples).sum();
    let mut state = Progress {
        samples_done: 0,
        samples_total,
        files_done: 0,
        files_total: plans.len(),
    };
    let mut files = Vec::with_capacity(plans.len());
    let networks = units
        .iter()
        .map(|u| {
            let network = match world {
                Some((w, _)) => u.thermal.network_with(&w.links),
                None => u.thermal.network(),
            };
            network.map_err(|reason| SimError::Physics {
                unit: u.unit_id.clone(),
                reason,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    // The thermal state is stepped exactly on the 100 Hz auxiliary grid (see engine).
    let grid_s = 1.0 / f64::from(drift_recording::AUX_RATE_HZ);
    let steps: Vec<_> = networks.iter().map(|n| n.discretise(grid_s)).collect();
    for (file, plan) in plans.iter().enumerate() {
        let u = plan.unit_index as usize;
        let sim = FileSim {
            campaign: c,
            unit: &units[u],
            network: &networks[u],
            step: &steps[u],
            plan,
            world: world.map(|(w, _)| w),
            world_aux: world.and_then(|(_, aux)| aux.get(file)).map_or(&[], |a| a),
        };
        let rec_path = recordings.join(format!("{}.mcap", plan.stem));
        let truth_path = truth.join(format!("{}.{TRUTH_EXTENSION}", plan.stem));
        let counts = sim.run(&rec_path, &truth_path, &mut |n| {
            state.samples_done += n;
            progress(state)
        })?;
        state.files_done += 1;
        if progress(state).is_break() {
            return Err(SimError::Interrupted);
        }
        files.push(FileSummary {
            recording: rec_path,
            truth: truth_path,
            unit_id: units[u].unit_id.clone(),
            set_point_celsius: plan.set_point_c,
            series_kind: plan.kind,
            activations: counts.activations,
            samples: counts.samples,
            recording_bytes: counts.recording_bytes,
            truth_bytes: counts.truth_bytes,
        });
    }
    let summary = Summary {
        campaign: c.name.clone(),
        samples: files.iter().map(|f| f.samples).sum(),
        recording_bytes: files.iter().map(|f| f.recording_bytes).sum(),
        truth_bytes: files.iter().map(|f| f.truth_bytes).sum(),
        files,
        wall_s: started.elapsed().as_secs_f64(),
    };
    write_json(&marker, &summary)?;
    Ok(summary)
}
