//! The closed loop on worlds it was not built with (run by `examples/worlds.rs`, checked by
//! `tests/worlds.rs`; the table is in this crate's README, *worlds*).
//!
//! Per world, three steps that share nothing but folders:
//!
//! 1. [`record`]: draw the world (`drift_sim::world`), record its campaign into a recordings
//!    folder, the zero-drift twin's into another, and the world's truth into a file elsewhere.
//!    The simulator's own truth sidecars (`<dir>/truth/`) are deleted at once.
//! 2. [`close_blind`]: read the two recordings folders only; fit the paper's tables on the
//!    calibration protocol, close the loop (`drift_diagnose::closing::close`, extended model on),
//!    and keep what the loop said (rankings, terms the guard admitted) and the drift of every
//!    held-out +33 °C field activation before and after, beside the twin's (the noise floor).
//! 3. [`score`]: only now read the truth, and score each axis against it.
//!
//! The candidate → family mapping is [`families_named`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use drift_evaluate::excess::{excess_cut, ExcessCut};
use drift_fit::FitSettings;
use drift_recording::{paper, Segment, RECORDINGS_DIR, TRUTH_DIR};
use drift_sim::world::effects::{EffectFamily, Source};
use drift_sim::world::{World, WorldCampaign, WorldSpec, WorldTruth};
use serde::{Deserialize, Serialize};

use crate::closed_loop::segments;
use crate::judged::judged_axes;
pub use crate::judged::{AxisOutcome, Ranked, AXES};
pub use crate::memory::peak_rss_mb;
use crate::oracle::{close_oracle, OracleAxis, OracleOutcome};
use crate::world_loop::fit_and_close;

/// The set point the loop is measured at (°C): the world campaign's validation one.
pub const VALIDATION: f64 = paper::VALIDATION_SET_POINT_CELSIUS;
/// Calibration set points (°C).
pub const CALIBRATION: [f64; 2] = paper::CALIBRATION_SET_POINTS_CELSIUS;
/// Seeds of the benchmark start here by default: above every seed the repository's tests and
/// examples use.
pub const DEFAULT_FIRST_SEED: u64 = 10_000;
/// A truth term moving the bias by less than this over its feature's span (°/s) does not make its
/// axis affected: a tenth of the smallest size an effect is drawn at (`TARGET_DPS × 0.5`).
pub const NEGLIGIBLE_DPS: f64 = 1.5e-4;
/// The element heating rate's span the simulator sizes `temperature_rate` on (°C/s).
const ELEMENT_RATE_SPAN_C_PER_S: f64 = 0.04;
/// An extended model is "worse" on a null axis when its drift excess cut is surely below this.
pub const WORSE_BELOW: f64 = 0.9;

/// What a world is drawn with: one effect family, or none.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `WorldSpec::with(&[family])`.
    Effect(EffectFamily),
    /// `WorldSpec::null()`.
    Null,
}

impl Kind {
    /// The family's name, or `null`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Effect(f) => f.name(),
            Self::Null => "null",
        }
    }

    /// Reads what [`Self::name`] writes.
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        if text == "null" {
            return Ok(Self::Null);
        }
        EffectFamily::ALL
            .into_iter()
            .find(|f| f.name() == text)
            .map(Self::Effect)
            .with_context(|| {
                let names: Vec<&str> = EffectFamily::ALL.iter().map(|f| f.name()).collect();
                format!("`{text}` is no family (null, {})", names.join(", "))
            })
    }

    /// Whether the world's effect is an additive bias an oracle can regress on (every family but
    /// self-heating, which changes the heating itself).
    pub fn has_oracle(self) -> bool {
        matches!(self, Self::Effect(f) if f != EffectFamily::SelfHeating)
    }

    /// The world spec: only this family at `magnitude` × the realistic size, or a null world.
    pub fn spec(self, magnitude: f64) -> WorldSpec {
        match self {
            Self::Effect(f) => WorldSpec {
                magnitude_scale: magnitude,
                ..WorldSpec::with(&[f])
            },
            Self::Null => WorldSpec::null(),
        }
    }
}

/// The campaign recorded per world: the default world campaign (+30/+40 °C protocol 1–30 min
/// twice, two field sessions of 8 activations per set point, +33 °C validation, 1000 Hz), or with
/// `small` a smoke-sized one: 200 Hz, protocol off-times 1, 5 and 30 min once, one field session
/// of 8 per set point.
pub fn world_campaign(small: bool) -> WorldCampaign {
    if small {
        WorldCampaign {
            sample_rate_hz: 200,
            intervals_min: vec![1.0, 5.0, 30.0],
            repeats: 1,
            field_sessions: 1,
            ..WorldCampaign::default()
        }
    } else {
        WorldCampaign::default()
    }
}

/// The fit's settings for [`world_campaign`]: the defaults as the loop runs them on its block
/// means ([`drift_diagnose::activations::loop_settings`]).
pub fn fit_settings() -> FitSettings {
    drift_diagnose::activations::loop_settings(&FitSettings::default())
}

/// Where one world's files go.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WorldPaths {
    /// The world's campaign (`<dir>/recordings/`).
    pub dir: PathBuf,
    /// The zero-drift twin's campaign.
    pub floor_dir: PathBuf,
    /// The analyst's diagnosis campaign, when one is recorded.
    pub diagnosis_dir: PathBuf,
    /// The truth file (outside both).
    pub truth: PathBuf,
    /// The simulator's sidecars of the world's and the diagnosis campaign's recordings
    /// (`world/`, `diagnosis/`): read by the oracle only ([`crate::oracle`]).
    pub oracle_dir: PathBuf,
}

impl WorldPaths {
    /// `<work>/<kind>-<seed>/world`, `<work>/<kind>-<seed>/floor` and `<work>/truth/<kind>-<seed>.json`.
    pub fn new(work: &Path, kind: Kind, seed: u64) -> Self {
        let name = format!("{}-{seed}", kind.name());
        Self {
            dir: work.join(&name).join("world"),
            floor_dir: work.join(&name).join("floor"),
            diagnosis_dir: work.join(&name).join("diagnosis"),
            truth: work.join("truth").join(format!("{name}.json")),
            oracle_dir: work.join(&name).join("oracle"),
        }
    }

    /// Deletes the recordings (the truth file stays until [`Self::remove_truth`]).
    pub fn remove_recordings(&self) {
        if let Some(parent) = self.dir.parent() {
            let _ = std::fs::remove_dir_all(parent);
        }
    }

    /// Deletes the truth file.
    pub fn remove_truth(&self) {
        let _ = std::fs::remove_file(&self.truth);
    }
}

/// What recording one world cost.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Recorded {
    /// Wall time of the world's campaign and the twin's, s.
    pub seconds: f64,
    /// Bytes of the world's recordings.
    pub bytes: u64,
    /// Peak resident memory of the process at the end, MB.
    pub peak_rss_mb: f64,
}

/// Step 1: draws the world of `seed`, records its campaign into `paths.dir` and its zero-drift
/// twin's (field sessions at +33 °C, behind a one-series protocol the campaign needs) into
/// `paths.floor_dir`, and writes the truth to `paths.truth`. The simulator's truth sidecars move
/// to `paths.oracle_dir` (the twin's are deleted): the recordings folders are all the blind loop
/// reads. An effect world's family is drawn at `magnitude` × its realistic size.
///
/// With `diagnosis_series` > 0 the unit also records an analyst's diagnosis campaign into
/// `paths.diagnosis_dir`: that many ramped field series of 5 activations at the validation set
/// point (no protocol), on a schedule of its own.
pub fn record(
    kind: Kind,
    seed: u64,
    paths: &WorldPaths,
    small: bool,
    diagnosis_series: u32,
    magnitude: f64,
) -> anyhow::Result<Recorded> {
    let started = Instant::now();
    let plan = world_campaign(small);
    let world = World::draw(seed, &kind.spec(magnitude));
    let summary = world
        .simulate(&world.campaign(&plan), &paths.dir, |_| {})
        .with_context(|| format!("simulating the {} world of seed {seed}", kind.name()))?;
    let twin = world.zero_drift_twin();
    let mut floor = twin.campaign(&plan);
    floor.set_points_celsius = vec![VALIDATION];
    if let Some(p) = &mut floor.protocol {
        p.intervals_min = vec![30.0];
        p.repeats = 1;
    }
    twin.simulate(&floor, &paths.floor_dir, |_| {})
        .context("simulating the zero-drift twin")?;
    if diagnosis_series > 0 {
        let mut diagnosis = world.campaign(&plan);
        diagnosis.name = "diagnosis".into();
        // Its own schedule and noise: the diagnosis campaign is another day on the bench.
        diagnosis.seed ^= 0x00D1_A600;
        diagnosis.set_points_celsius = vec![VALIDATION];
        diagnosis.protocol = None;
        if let Some(field) = &mut diagnosis.field {
            field.sessions = diagnosis_series;
            field.activations = 5;
        }
        world
            .simulate(&diagnosis, &paths.diagnosis_dir, |_| {})
            .context("simulating the diagnosis campaign")?;
    }
    let _ = std::fs::remove_dir_all(paths.floor_dir.join(TRUTH_DIR));
    std::fs::create_dir_all(&paths.oracle_dir)?;
    for (dir, name) in [(&paths.dir, "world"), (&paths.diagnosis_dir, "diagnosis")] {
        let truth = dir.join(TRUTH_DIR);
        if truth.exists() {
            std::fs::rename(&truth, paths.oracle_dir.join(name))?;
        }
    }
    if let Some(parent) = paths.truth.parent() {
        std::fs::create_dir_all(parent)?;
    }
    world.write_truth(&paths.truth)?;
    Ok(Recorded {
        seconds: started.elapsed().as_secs_f64(),
        bytes: summary.recording_bytes,
        peak_rss_mb: peak_rss_mb(),
    })
}

/// What the loop said and measured, blind.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Outcome {
    /// Per axis.
    pub axes: Vec<AxisOutcome>,
    /// Training activations (field, calibration set points, inside the range).
    pub training_activations: usize,
    /// Wall time of reading, fitting, closing the loop and measuring, s.
    pub seconds: f64,
    /// Peak resident memory of the process at the end, MB.
    pub peak_rss_mb: f64,
}

/// Step 2: the loop, blind. Reads the world's recordings folder (`dir`) and the twin's
/// (`floor_dir`) and nothing else.
/// With `select_on_validation`, the +33 °C protocol activations join the diagnosis
/// (`Roles::select`); the before/after is on the +33 °C field activations either way.
///
/// With `diagnosis_dir` (an analyst's diagnosis campaign) the loop diagnoses on it, cross-fitted
/// by series (`closing::close_both`); the outcome is the first half's, judged on held-out series
/// that include the other half.
pub fn close_blind(
    dir: &Path,
    floor_dir: &Path,
    settings: &FitSettings,
    select_on_validation: bool,
    diagnosis_dir: Option<&Path>,
) -> anyhow::Result<Outcome> {
    let started = Instant::now();
    let all = segments(&dir.join(RECORDINGS_DIR))?;
    let diagnosis = match diagnosis_dir {
        Some(d) => segments(&d.join(RECORDINGS_DIR))?,
        None => Vec::new(),
    };
    let diagnosis: Vec<&Segment> = diagnosis.iter().collect();
    let (base, closed) = fit_and_close(&all, &diagnosis, true, select_on_validation, settings)?;
    let axes = judged_axes(&base, &closed, floor_dir, settings)?;
    Ok(Outcome {
        axes,
        training_activations: closed.roles.training.len(),
        seconds: started.elapsed().as_secs_f64(),
        peak_rss_mb: peak_rss_mb(),
    })
}

/// The families a candidate's name points at (what "the right family" means). The auxiliary
/// channel names a channel family, with or without an interaction behind it
/// (`aux:humidity × rise X` is humidity's); the rates name `temperature_rate`; another axis's rise
/// names `cross_axis` and `other_sensor_temperature` (and `element_temperature` where the truth's
/// term on the axis reads another axis's element: checked in [`score`]); the axis's own
/// temperature level and curvature (`rise²`, the switch-on temperature, the chamber set point,
/// a `temperature` candidate) name `element_temperature` and `self_heating`. Time since
/// switch-on, residual heat and campaign time name none.
pub fn families_named(candidate: &str) -> Vec<EffectFamily> {
    use EffectFamily::*;
    if let Some(rest) = candidate.strip_prefix("aux:") {
        let channel = rest.split([' ', '×']).next().unwrap_or("");
        return match channel {
            c if c.starts_with("accel") => vec![Accelerometer],
            c if c.starts_with("supply_voltage") => vec![SupplyVoltage],
            c if c.starts_with("humidity") => vec![Humidity],
            c if c.starts_with("air_pressure") => vec![AirPressure],
            c if c.starts_with("chamber_set_point") => vec![ElementTemperature, SelfHeating],
            _ => Vec::new(),
        };
    }
    if candidate.starts_with("temperature rate") || candidate.starts_with("element rate") {
        return vec![TemperatureRate];
    }
    if candidate.starts_with("rise²")
        || candidate.starts_with("switch-on temperature")
        || candidate.starts_with("temperature ")
    {
        return vec![ElementTemperature, SelfHeating];
    }
    if candidate.starts_with("rise ") {
        return vec![CrossAxis, OtherSensorTemperature];
    }
    Vec::new()
}

/// Whether `candidate`, top on `axis`, names the world's family there.
fn names_family(candidate: &str, truth: &WorldTruth, family: EffectFamily, axis: usize) -> bool {
    if families_named(candidate).contains(&family) {
        return true;
    }
    // Another axis's element temperature (element_temperature on another axis) shows as that
    // axis's rise.
    family == EffectFamily::ElementTemperature
        && candidate.starts_with("rise ")
        && truth.effects.iter().flat_map(|e| &e.terms).any(|t| {
            t.axis == axis
                && matches!(t.source, Source::ElementTemperature { axis: b } if b != axis)
        })
}

/// The axes a world's effects move by more than [`NEGLIGIBLE_DPS`].
pub fn affected_axes(truth: &WorldTruth) -> [bool; 3] {
    let mut out = [false; 3];
    for e in &truth.effects {
        for t in &e.terms {
            if t.sized_dps >= NEGLIGIBLE_DPS && t.axis < 3 {
                out[t.axis] = true;
            }
        }
        if let Some(k) = e.rate_dps_per_c_per_s {
            for (o, k) in out.iter_mut().zip(k) {
                *o |= k.abs() * ELEMENT_RATE_SPAN_C_PER_S >= NEGLIGIBLE_DPS;
            }
        }
        // Self-heating changes every ASIC's power.
        if e.asic_power_per_c.is_some_and(|a| a > 0.0) {
            out = [true; 3];
        }
    }
    out
}

/// One axis of one world, scored against the truth.
#[derive(Debug, Clone, Serialize)]
pub struct AxisScore {
    /// `X`, `Y` or `Z`.
    pub axis: &'static str,
    /// Whether the world's effect moves this axis.
    pub affected: bool,
    /// The top effect behind the loop's model ("–" when none): the first candidate that is not
    /// the unit's own thermal response.
    pub top: String,
    /// Whether it is significant.
    pub top_significant: bool,
    /// Whether it names the world's family ([`families_named`]; false on a null world).
    pub right_family: bool,
    /// Whether a term naming the world's family was admitted on the axis.
    pub right_family_admitted: bool,
    /// Whether any effect on the axis is significant.
    pub any_significant: bool,
    /// The unit's own thermal response selected on the axis, in order.
    pub thermal_response: Vec<String>,
    /// The explained share a candidate had to exceed to be significant on this axis.
    pub detectable_share: f64,
    /// Terms admitted on the axis.
    pub admitted: Vec<String>,
    /// Terms the guard left out on the axis, with its reasons.
    pub refused: Vec<String>,
    /// Mean drift before, after, and the floor's, °/s.
    pub drift: (f64, f64, f64),
    /// Every candidate as the loop ranked it, best first, with whether it names the world's
    /// family: what a threshold calibrated on null worlds is computed from.
    pub ranking: Vec<(Ranked, bool)>,
    /// The drift excess cut over the floor with its 95 % interval.
    pub cut: ExcessCut,
    /// What the loop's diagnosis made of the true regressor on the same data (effect worlds with
    /// an oracle run).
    pub oracle: Option<OracleAxis>,
}

impl AxisScore {
    /// The true regressor clears the detectable share here.
    pub fn oracle_detectable(&self) -> bool {
        self.oracle.as_ref().is_some_and(OracleAxis::detectable)
    }

    /// Right family, ranked first, significant.
    pub fn found(&self) -> bool {
        self.right_family && self.top_significant
    }

    /// The extended model is worse than [`WORSE_BELOW`]× with 95 % confidence.
    pub fn surely_worse(&self) -> bool {
        self.cut.ratio > 0.0 && self.cut.surely_below(WORSE_BELOW)
    }
}

/// One world, scored.
#[derive(Debug, Clone, Serialize)]
pub struct WorldScore {
    /// The family (or `null`).
    pub kind: &'static str,
    /// The seed.
    pub seed: u64,
    /// The forms drawn (channel families), for the record.
    pub forms: Vec<String>,
    /// Per axis.
    pub axes: Vec<AxisScore>,
    /// Wall time of recording the world and its twin, s.
    pub record_seconds: f64,
    /// Wall time of the loop, s.
    pub loop_seconds: f64,
    /// Peak resident memory of the loop's process, MB.
    pub loop_peak_rss_mb: f64,
    /// Peak resident memory of the recording's process, MB.
    pub record_peak_rss_mb: f64,
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// Step 3: reads the truth file and scores the loop's outcome against it.
pub fn score(
    kind: Kind,
    seed: u64,
    truth_path: &Path,
    recorded: &Recorded,
    outcome: &Outcome,
    oracle: Option<&OracleOutcome>,
) -> anyhow::Result<WorldScore> {
    let text = std::fs::read_to_string(truth_path)
        .with_context(|| format!("reading {}", truth_path.display()))?;
    let truth: WorldTruth = serde_json::from_str(&text)?;
    let family = match kind {
        Kind::Effect(f) => Some(f),
        Kind::Null => None,
    };
    anyhow::ensure!(
        truth.families() == family.into_iter().collect::<Vec<_>>(),
        "the truth's families {:?} are not the world's {:?}",
        truth.families(),
        family
    );
    let affected = affected_axes(&truth);
    let axes = outcome
        .axes
        .iter()
        .enumerate()
        .map(|(a, o)| {
            let top = o.ranking.iter().find(|c| !c.thermal_response);
            let names = |c: &str| family.is_some_and(|f| names_family(c, &truth, f, a));
            AxisScore {
                axis: AXES[a],
                affected: affected[a],
                top: top.map_or("–".into(), |c| c.name.clone()),
                top_significant: top.is_some_and(|c| c.significant),
                right_family: top.is_some_and(|c| names(&c.name)),
                right_family_admitted: o.admitted.iter().any(|c| names(c)),
                any_significant: o.any_significant,
                thermal_response: o
                    .ranking
                    .iter()
                    .filter(|c| c.thermal_response && c.significant)
                    .map(|c| c.name.clone())
                    .collect(),
                detectable_share: o.detectable_share,
                admitted: o.admitted.clone(),
                refused: o.refused.clone(),
                drift: (mean(&o.before_dps), mean(&o.after_dps), mean(&o.floor_dps)),
                ranking: o
                    .ranking
                    .iter()
                    .map(|c| (c.clone(), names(&c.name)))
                    .collect(),
                cut: excess_cut(&o.before_dps, &o.after_dps, &o.floor_dps),
                oracle: oracle.and_then(|x| x.axes.get(a).cloned().flatten()),
            }
        })
        .collect();
    Ok(WorldScore {
        kind: kind.name(),
        seed,
        forms: truth
            .effects
            .iter()
            .filter_map(|e| e.form.map(|f| f.name().to_owned()))
            .collect(),
        axes,
        record_seconds: recorded.seconds,
        loop_seconds: outcome.seconds,
        loop_peak_rss_mb: outcome.peak_rss_mb,
        record_peak_rss_mb: recorded.peak_rss_mb,
    })
}

/// All three steps in this process (the example runs each in a child process of its own, for
/// the memory figures): record, close blind, score, then delete the world's files.
/// An effect world's family is drawn at `magnitude` × its realistic size; its oracle runs after
/// the blind loop.
pub fn run_world(
    kind: Kind,
    seed: u64,
    work: &Path,
    small: bool,
    magnitude: f64,
) -> anyhow::Result<WorldScore> {
    let paths = WorldPaths::new(work, kind, seed);
    let recorded = record(kind, seed, &paths, small, 0, magnitude);
    let outcome = recorded
        .as_ref()
        .ok()
        .map(|_| close_blind(&paths.dir, &paths.floor_dir, &fit_settings(), false, None));
    let oracle = match &outcome {
        Some(Ok(_)) if kind.has_oracle() => Some(close_oracle(
            &paths.dir,
            None,
            &paths.oracle_dir,
            &paths.floor_dir,
            &fit_settings(),
            false,
        )),
        _ => None,
    };
    paths.remove_recordings();
    let result = match (recorded, outcome, oracle.transpose()) {
        (_, _, Err(e)) => Err(e),
        (Ok(r), Some(Ok(o)), Ok(x)) => score(kind, seed, &paths.truth, &r, &o, x.as_ref()),
        (Err(e), _, _) | (_, Some(Err(e)), _) => Err(e),
        (Ok(_), None, _) => unreachable!("the loop runs after a recording"),
    };
    paths.remove_truth();
    result
}

/// Wilson's 95 % interval of `k` successes in `n`, as fractions.
pub fn wilson(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (k, n, z) = (k as f64, n as f64, 1.96_f64);
    let p = k / n;
    let denominator = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denominator;
    let half = z / denominator * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// "k of n (p %, lo–hi %)".
fn share(k: usize, n: usize) -> String {
    if n == 0 {
        return "0 of 0".to_owned();
    }
    let (lo, hi) = wilson(k, n);
    format!(
        "{k} of {n} ({:.0} %, {:.0}–{:.0} %)",
        100.0 * k as f64 / n as f64,
        100.0 * lo,
        100.0 * hi
    )
}

fn ratio_text(v: f64) -> String {
    if v > 99.0 {
        "> 99×".to_owned()
    } else {
        format!("{v:.2}×")
    }
}

fn median(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

/// "median (lowest–highest)" of sorted cuts, "–" for none.
fn cut_range(sorted: &[f64]) -> String {
    match (sorted.first(), sorted.last()) {
        (Some(&low), Some(&high)) => format!(
            "{} ({}–{})",
            ratio_text(median(sorted)),
            ratio_text(low),
            ratio_text(high)
        ),
        _ => "–".to_owned(),
    }
}

/// The cuts of axes with an excess to cut (before above the floor), sorted.
fn cuts(axes: &[&AxisScore]) -> Vec<f64> {
    let mut v: Vec<f64> = axes
        .iter()
        .map(|a| a.cut.ratio)
        .filter(|r| r.is_finite() && *r > 0.0)
        .collect();
    v.sort_by(f64::total_cmp);
    v
}

/// A world the benchmark could not score (recording or loop failed).
#[derive(Debug, Clone)]
pub struct Failure {
    /// The family (or `null`).
    pub kind: &'static str,
    /// The seed.
    pub seed: u64,
    /// What went wrong.
    pub error: String,
}

/// The Markdown tables: per family, then the null worlds, then time and memory per world (and
/// the worlds that failed, which no other row counts).
pub fn table(scores: &[WorldScore], failures: &[Failure], kinds: &[Kind]) -> String {
    let mut out = String::new();
    out.push_str("| family | worlds | affected axes | oracle: true regressor's gain, median (range) | oracle-detectable axes | right family first and significant among them | right family ranked first and significant | right family first (any significance) | right family admitted | drift excess cut, median (range) | oracle: drift excess cut where it admitted a term, median (range) | axes surely worse than 0.9× |\n");
    out.push_str("|---|---:|---:|---|---:|---|---|---|---|---|---|---:|\n");
    for kind in kinds.iter().filter(|k| **k != Kind::Null) {
        let worlds: Vec<&WorldScore> = scores.iter().filter(|s| s.kind == kind.name()).collect();
        let affected: Vec<&AxisScore> = worlds
            .iter()
            .flat_map(|w| &w.axes)
            .filter(|a| a.affected)
            .collect();
        let n = affected.len();
        let count = |f: &dyn Fn(&AxisScore) -> bool| affected.iter().filter(|a| f(a)).count();
        let cut = cut_range(&cuts(&affected));
        let mut oracle_cuts: Vec<f64> = affected
            .iter()
            .filter_map(|a| a.oracle.as_ref())
            .filter(|o| !o.terms.is_empty() && o.cut.ratio > 0.0)
            .map(|o| o.cut.ratio)
            .collect();
        oracle_cuts.sort_by(f64::total_cmp);
        let oracle_cut = cut_range(&oracle_cuts);
        let mut gains: Vec<f64> = affected
            .iter()
            .filter_map(|a| a.oracle.as_ref().map(|o| o.gain))
            .collect();
        gains.sort_by(f64::total_cmp);
        let gain = if gains.is_empty() {
            "–".to_owned()
        } else {
            format!(
                "{:.2} ({:.2}–{:.2})",
                median(&gains),
                gains[0],
                gains[gains.len() - 1]
            )
        };
        let detectable = count(&AxisScore::oracle_detectable);
        out.push_str(&format!(
            "| {} | {} | {} | {gain} | {} | {} | {} | {} | {} | {} | {oracle_cut} | {} |\n",
            kind.name(),
            worlds.len(),
            n,
            if gains.is_empty() {
                "–".to_owned()
            } else {
                detectable.to_string()
            },
            share(count(&|a| a.oracle_detectable() && a.found()), detectable),
            share(count(&AxisScore::found), n),
            share(count(&|a| a.right_family), n),
            share(count(&|a| a.right_family_admitted), n),
            cut,
            count(&AxisScore::surely_worse),
        ));
    }
    if kinds.contains(&Kind::Null) {
        let worlds: Vec<&WorldScore> = scores.iter().filter(|s| s.kind == "null").collect();
        let axes: Vec<&AxisScore> = worlds.iter().flat_map(|w| &w.axes).collect();
        let n = axes.len();
        let quiet = axes.iter().filter(|a| !a.any_significant).count();
        let admitted = axes.iter().filter(|a| !a.admitted.is_empty()).count();
        let worse = axes.iter().filter(|a| a.surely_worse()).count();
        let worst = axes
            .iter()
            .filter(|a| a.cut.ratio.is_finite() && a.cut.ratio > 0.0)
            .min_by(|a, b| a.cut.ratio.total_cmp(&b.cut.ratio));
        out.push_str("\n| null | worlds | axes | nothing significant | a term admitted | surely worse than 0.9× | worst drift excess cut (95 % interval) |\n");
        out.push_str("|---|---:|---:|---|---|---:|---|\n");
        out.push_str(&format!(
            "| null | {} | {n} | {} | {} | {worse} | {} |\n",
            worlds.len(),
            share(quiet, n),
            share(admitted, n),
            worst.map_or("–".to_owned(), |a| format!("{}", a.cut)),
        ));
    }
    out.push_str("\n| worlds | scored | failed | record world + twin, s: median (max) | loop, s: median (max) | loop peak RSS, MB: max |\n");
    out.push_str("|---|---:|---:|---|---|---:|\n");
    for kind in kinds {
        let worlds: Vec<&WorldScore> = scores.iter().filter(|s| s.kind == kind.name()).collect();
        let failed = failures.iter().filter(|f| f.kind == kind.name()).count();
        if worlds.is_empty() {
            out.push_str(&format!("| {} | 0 | {failed} | – | – | – |\n", kind.name()));
            continue;
        }
        let sorted = |f: &dyn Fn(&WorldScore) -> f64| {
            let mut v: Vec<f64> = worlds.iter().map(|w| f(w)).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (rec, lp, rss) = (
            sorted(&|w| w.record_seconds),
            sorted(&|w| w.loop_seconds),
            sorted(&|w| w.loop_peak_rss_mb),
        );
        out.push_str(&format!(
            "| {} | {} | {failed} | {:.1} ({:.1}) | {:.1} ({:.1}) | {:.0} |\n",
            kind.name(),
            worlds.len(),
            median(&rec),
            rec[rec.len() - 1],
            median(&lp),
            lp[lp.len() - 1],
            rss[rss.len() - 1],
        ));
    }
    out
}

/// One line per world and axis, for standard error and the record.
pub fn world_lines(s: &WorldScore) -> Vec<String> {
    s.axes
        .iter()
        .map(|a| {
            format!(
                "{} {} [{}] {}: affected {}, thermal response [{}], top effect {}{}, right family {}, admitted [{}], drift {:.4} → {:.4} (floor {:.4}) °/s, cut {}{}",
                s.kind,
                s.seed,
                s.forms.join(","),
                a.axis,
                a.affected,
                a.thermal_response.join(", "),
                a.top,
                if a.top_significant { " (significant)" } else { "" },
                a.right_family,
                a.admitted.join(", "),
                a.drift.0,
                a.drift.1,
                a.drift.2,
                a.cut,
                a.oracle.as_ref().map_or(String::new(), |o| format!(
                    ", oracle gain {:.3} (detectable from {:.3}, rank {}, {}, absorbed {:.2}), oracle admitted [{}], refused [{}], cut {}",
                    o.gain,
                    o.detectable_share,
                    o.rank,
                    o.level,
                    o.absorbed_by_model,
                    o.terms.join(", "),
                    o.refused.join("; "),
                    o.cut
                )),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn candidate_names_map_to_families() {
        use EffectFamily::*;
        assert_eq!(families_named("aux:accel_y"), [Accelerometer]);
        assert_eq!(families_named("aux:supply_voltage"), [SupplyVoltage]);
        assert_eq!(families_named("aux:humidity × rise X"), [Humidity]);
        assert_eq!(
            families_named("aux:air_pressure × temperature Z"),
            [AirPressure]
        );
        assert_eq!(
            families_named("temperature rate X (τ 8 s)"),
            [TemperatureRate]
        );
        assert_eq!(families_named("element rate Y (τ 30 s)"), [TemperatureRate]);
        assert_eq!(
            families_named("rise Z"),
            [CrossAxis, OtherSensorTemperature]
        );
        assert_eq!(families_named("rise² X"), [ElementTemperature, SelfHeating]);
        assert!(families_named("time since switch-on").is_empty());
        assert!(families_named("residual heat at switch-on (off-time)").is_empty());
        assert!(families_named("campaign time (ageing)").is_empty());
    }

    #[test]
    fn wilson_interval() {
        let (lo, hi) = wilson(10, 20);
        assert!(
            (lo - 0.299).abs() < 0.002 && (hi - 0.701).abs() < 0.002,
            "{lo} {hi}"
        );
        let (lo, hi) = wilson(0, 30);
        assert!(lo == 0.0 && (hi - 0.114).abs() < 0.002, "{hi}");
    }

    #[test]
    fn kinds_read_back() {
        for f in EffectFamily::ALL {
            assert_eq!(Kind::parse(f.name()).unwrap(), Kind::Effect(f));
        }
        assert_eq!(Kind::parse("null").unwrap(), Kind::Null);
        assert!(Kind::parse("nonsense").is_err());
    }
}
