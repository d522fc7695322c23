//! Worlds, not one simulator: per seed, a unit with its own structure and bench conditions, and
//! any subset of *undeclared effects*, each from a physically motivated family of forms, at
//! realistic magnitudes. The truth (structure, effects, forms, coefficients) goes to a file of its
//! own ([`World::write_truth`], `truth/world.json` by default), never into the recordings, which
//! carry the same bench channels whatever is switched on.
//!
//! ```no_run
//! use drift_sim::world::{simulate_world, WorldSpec};
//! let run = simulate_world(7, &WorldSpec::default(), std::path::Path::new("out/world-7"))?;
//! println!("truth in {}", run.truth_path.display());
//! # Ok::<(), drift_sim::SimError>(())
//! ```
//!
//! See `docs/simulator.md`, *Worlds*.

mod channels;
pub mod effects;
pub(crate) mod runtime;
pub mod structure;

use crate::campaign::{Campaign, Field, Protocol, TruthBias};
use crate::error::SimError;
use crate::rng;
use crate::schedule::{self, SeriesKind};
use crate::simulate::{record, write_json, Progress, Summary};
use crate::unit::{UnitModel, UnitParams, REFERENCE_CELSIUS};
use crate::HiddenEffects;
use effects::{Effect, EffectFamily, EffectForm};
use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use runtime::{AuxActivation, Runtime};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;
use structure::Structure;

pub use channels::{AIR_PRESSURE, AIR_PRESSURE_REFERENCE, HUMIDITY, HUMIDITY_REFERENCE};
/// The truth file's name in `<out>/truth/` when the caller gives no path.
pub const TRUTH_FILE: &str = "world.json";

/// What kind of world to draw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WorldSpec {
    /// The undeclared effects: `None` draws a random subset (each family on with
    /// `effect_probability`); `Some(list)` switches on exactly these (empty: a null world).
    pub families: Option<Vec<EffectFamily>>,
    /// The forms channel families may take (`None`: any of the family's).
    pub forms: Option<Vec<EffectForm>>,
    /// Probability of each family when `families` is `None`.
    pub effect_probability: f64,
    /// Multiplies every effect's size (1 = realistic: a few 10⁻³ °/s over an activation).
    pub magnitude_scale: f64,
    /// Draw the structure and bench conditions (`false`: the base model's, the default bench).
    pub vary_structure: bool,
}

impl Default for WorldSpec {
    fn default() -> Self {
        Self {
            families: None,
            forms: None,
            effect_probability: 0.3,
            magnitude_scale: 1.0,
            vary_structure: true,
        }
    }
}

impl WorldSpec {
    /// A null world: the same structural variation, no undeclared effect.
    pub fn null() -> Self {
        Self {
            families: Some(Vec::new()),
            ..Self::default()
        }
    }

    /// Exactly these families.
    pub fn with(families: &[EffectFamily]) -> Self {
        Self {
            families: Some(families.to_vec()),
            ..Self::default()
        }
    }
}

/// Everything a world is: for evaluation code only, never for the fitter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorldTruth {
    /// The seed it was drawn from.
    pub seed: u64,
    /// The spec it was drawn with.
    pub spec: WorldSpec,
    /// The unit the engine simulates (base parameters, plus the temperature-rate and
    /// self-heating coefficients when those effects are on).
    pub unit: UnitParams,
    /// Structure and bench conditions.
    pub structure: Structure,
    /// The undeclared effects (empty in a null world).
    pub effects: Vec<Effect>,
}

impl WorldTruth {
    /// The families switched on.
    pub fn families(&self) -> Vec<EffectFamily> {
        self.effects.iter().map(|e| e.family).collect()
    }
}

/// One drawn world.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    truth: WorldTruth,
}

fn world_stream(seed: u64, path: &[u64]) -> ChaCha8Rng {
    let mut full = vec![rng::tag("world")];
    full.extend_from_slice(path);
    rng::stream(seed, &full)
}

/// The unit's mean |∂b/∂T_e| at about +35 °C ((°/s)/°C).
fn mean_abs_tempco(unit: &UnitParams) -> f64 {
    let per_c = crate::bias::relative_pressure(REFERENCE_CELSIUS + 1.0) - 1.0;
    unit.axes
        .iter()
        .map(|a| {
            (a.tempco_dps_per_c + 2.0 * a.tempco2_dps_per_c2 * 10.0 + a.pressure_dps * per_c).abs()
        })
        .sum::<f64>()
        / 3.0
}

impl World {
    /// Draws the world of `seed`. Deterministic; each part (unit, structure, which families, each
    /// family's effect) comes from a stream of its own, so a null world and a world with effects
    /// drawn from the same seed share the unit and the structure.
    pub fn draw(seed: u64, spec: &WorldSpec) -> Self {
        let mut unit = UnitParams::draw(seed, 0, UnitModel::Physical, &HiddenEffects::default());
        let structure = if spec.vary_structure {
            Structure::draw(&mut world_stream(seed, &[rng::tag("structure")]))
        } else {
            Structure::plain()
        };
        let families: Vec<EffectFamily> = match &spec.families {
            Some(list) => EffectFamily::ALL
                .into_iter()
                .filter(|f| list.contains(f))
                .collect(),
            None => {
                let mut r = world_stream(seed, &[rng::tag("families")]);
                EffectFamily::ALL
                    .into_iter()
                    .filter(|_| r.random::<f64>() < spec.effect_probability)
                    .collect()
            }
        };
        let tempco = mean_abs_tempco(&unit);
        let mut effects = Vec::new();
        for family in families {
            let mut r = world_stream(seed, &[rng::tag("effect"), rng::tag(family.name())]);
            let forms = spec.forms.as_deref();
            if let Some(e) = effects::draw(family, &mut r, spec.magnitude_scale, forms, tempco) {
                if let Some(k) = e.rate_dps_per_c_per_s {
                    for (axis, k) in unit.axes.iter_mut().zip(k) {
                        axis.thermal_lag_dps_per_c_per_s = k;
                    }
                }
                if let Some(alpha) = e.asic_power_per_c {
                    unit.asic_power_per_c = alpha;
                }
                effects.push(e);
            }
        }
        Self {
            truth: WorldTruth {
                seed,
                spec: spec.clone(),
                unit,
                structure,
                effects,
            },
        }
    }

    /// The world's truth (serialisable: [`Self::write_truth`]).
    pub fn truth(&self) -> &WorldTruth {
        &self.truth
    }

    /// The same unit and structure without any undeclared effect.
    pub fn null_twin(&self) -> Self {
        let mut truth = self.truth.clone();
        truth.effects.clear();
        truth.spec.families = Some(Vec::new());
        for a in &mut truth.unit.axes {
            a.thermal_lag_dps_per_c_per_s = 0.0;
        }
        truth.unit.asic_power_per_c = 0.0;
        Self { truth }
    }

    /// The noise floor: the same unit (heating, noise, structure, bench) with no systematic drift
    /// at all (zero temperature coefficients, no undeclared effect).
    pub fn zero_drift_twin(&self) -> Self {
        let mut twin = self.null_twin();
        twin.truth.unit.model = UnitModel::ZeroSystematicDrift;
        for a in &mut twin.truth.unit.axes {
            a.tempco_dps_per_c = 0.0;
            a.tempco2_dps_per_c2 = 0.0;
            a.pressure_dps = 0.0;
        }
        twin
    }

    /// The campaign of this world: the calibration protocol and field-like sessions at the
    /// calibration set points and the validation set point, with the world's heating scatter and
    /// field ambient. One unit; its seed is the world's.
    pub fn campaign(&self, plan: &WorldCampaign) -> Campaign {
        let s = &self.truth.structure;
        let mut set_points = plan.calibration_celsius.clone();
        set_points.push(plan.validation_celsius);
        Campaign {
            name: "world".into(),
            seed: self.truth.seed,
            units: 1,
            sample_rate_hz: plan.sample_rate_hz,
            set_points_celsius: set_points,
            unit_model: self.truth.unit.model,
            noise_scale: plan.noise_scale,
            protocol: Some(Protocol {
                intervals_min: plan.intervals_min.clone(),
                repeats: plan.repeats,
                heating_scatter: s.protocol_heating_scatter,
                // A world's chamber wanders by its own drawn structure (`chamber_wander_c_per_min`).
                chamber_ripple_c: 0.0,
                ..Protocol::default()
            }),
            field: Some(Field {
                sessions: plan.field_sessions,
                activations: plan.field_activations,
                ambient_ramp_c_per_min: s.field_ambient_ramp_c_per_min,
                carry_probability: s.field_carry_probability,
                heating_scatter: s.field_heating_scatter,
                ..Field::default()
            }),
            effects: HiddenEffects::default(),
            truth_bias: TruthBias::AuxRate,
            ..Campaign::default()
        }
    }

    /// Records `c` (one unit: usually [`Self::campaign`], possibly edited) as this world into
    /// `out_dir`, like [`crate::simulate_campaign`]. The campaign's `unit_model` and `effects` are
    /// not used: the world is the unit. Writes no world truth: see [`Self::write_truth`].
    pub fn simulate(
        &self,
        c: &Campaign,
        out_dir: &Path,
        mut progress: impl FnMut(Progress),
    ) -> Result<Summary, SimError> {
        c.validate()?;
        if c.units != 1 {
            return Err(SimError::campaign(
                "units",
                "a world is one unit: must be 1",
            ));
        }
        let started = Instant::now();
        let s = &self.truth.structure;
        let mut plans = schedule::plan(c);
        let mut aux = Vec::with_capacity(plans.len());
        for plan in &mut plans {
            let file = u64::from(plan.file_index);
            if plan.kind == SeriesKind::Protocol && s.chamber_wander_c_per_min > 0.0 {
                let mut r = world_stream(c.seed, &[rng::tag("wander"), file]);
                for act in &mut plan.activations {
                    act.ambient_ramp_c_per_s =
                        s.chamber_wander_c_per_min / 60.0 * (2.0 * r.random::<f64>() - 1.0);
                }
            }
            let mut r = world_stream(c.seed, &[rng::tag("aux"), file]);
            aux.push(aux_schedule(&mut r, plan.activations.len()));
        }
        let mut runtime = Runtime::new(&self.truth.unit, s, &self.terms());
        runtime.rate_is_effect = self
            .truth
            .effects
            .iter()
            .any(|e| e.rate_dps_per_c_per_s.is_some());
        let units = [self.truth.unit.clone()];
        record(
            c,
            &units,
            &plans,
            Some((&runtime, &aux)),
            out_dir,
            started,
            &mut |p| {
                progress(p);
                std::ops::ControlFlow::Continue(())
            },
        )
    }

    /// Writes the truth as JSON to `path` (its folder must exist).
    pub fn write_truth(&self, path: &Path) -> Result<(), SimError> {
        write_json(path, &self.truth)
    }

    fn terms(&self) -> Vec<effects::Term> {
        self.truth
            .effects
            .iter()
            .flat_map(|e| e.terms.iter().cloned())
            .collect()
    }
}

/// The named channels of one file: humidity within ±4 %RH of a per-file level, ramping by up to
/// ±1.5 %RH/min in an activation; barometric pressure wandering by ±1.5 hPa between activations.
fn aux_schedule(r: &mut ChaCha8Rng, activations: usize) -> Vec<AuxActivation> {
    let mut uniform = |lo: f64, hi: f64| lo + (hi - lo) * r.random::<f64>();
    let humidity_level = uniform(25.0, 55.0);
    let mut pressure = uniform(1000.0, 1025.0);
    (0..activations)
        .map(|_| {
            let humidity = (humidity_level + uniform(-4.0, 4.0)).clamp(5.0, 95.0);
            let humidity_ramp = uniform(-1.5, 1.5) / 60.0;
            pressure += uniform(-1.5, 1.5);
            let pressure_ramp = uniform(-0.05, 0.05) / 60.0;
            AuxActivation {
                start: vec![humidity, pressure],
                ramp_per_s: vec![humidity_ramp, pressure_ramp],
            }
        })
        .collect()
}

/// What [`World::campaign`] records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WorldCampaign {
    /// Output rate (Hz).
    pub sample_rate_hz: u32,
    /// Calibration set points (°C).
    pub calibration_celsius: Vec<f64>,
    /// Validation set point (°C), recorded last.
    pub validation_celsius: f64,
    /// Protocol off-times (min).
    pub intervals_min: Vec<f64>,
    /// Repeats of each protocol series.
    pub repeats: u32,
    /// Field sessions per set point.
    pub field_sessions: u32,
    /// Activations per field session.
    pub field_activations: u32,
    /// 1 = physical noise, 0 = noise-free.
    pub noise_scale: f64,
}

impl Default for WorldCampaign {
    /// The closed loop's campaign: +30/+40 °C calibration, +33 °C validation, protocol off-times
    /// 1–30 min twice, two field sessions of 8 activations per set point.
    fn default() -> Self {
        Self {
            sample_rate_hz: 1000,
            calibration_celsius: vec![30.0, 40.0],
            validation_celsius: 33.0,
            intervals_min: vec![1.0, 2.0, 5.0, 10.0, 30.0],
            repeats: 2,
            field_sessions: 2,
            field_activations: 8,
            noise_scale: 1.0,
        }
    }
}

/// Options of [`simulate_world_with`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorldRunOptions {
    /// The campaign recorded.
    pub campaign: WorldCampaign,
    /// Where the truth goes (`None`: `<out>/truth/world.json`).
    pub truth_path: Option<PathBuf>,
    /// Also record the zero-drift twin (the noise floor) into `<out>/zero_drift/`.
    pub zero_drift_twin: bool,
}

/// What [`simulate_world`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldRun {
    /// The world's recordings (`<out>/recordings/`) and their sidecars.
    pub summary: Summary,
    /// The world's truth file.
    pub truth_path: PathBuf,
    /// The zero-drift twin's run (`<out>/zero_drift/`), when asked for.
    pub zero_drift: Option<Summary>,
}

/// Draws the world of `seed` and records its default campaign ([`WorldCampaign::default`]) into
/// `out_dir`, with its truth in `<out>/truth/world.json`.
pub fn simulate_world(seed: u64, spec: &WorldSpec, out_dir: &Path) -> Result<WorldRun, SimError> {
    simulate_world_with(seed, spec, out_dir, &WorldRunOptions::default())
}

/// [`simulate_world`] with a campaign, a truth path and the zero-drift twin to choose.
pub fn simulate_world_with(
    seed: u64,
    spec: &WorldSpec,
    out_dir: &Path,
    options: &WorldRunOptions,
) -> Result<WorldRun, SimError> {
    let world = World::draw(seed, spec);
    let summary = world.simulate(&world.campaign(&options.campaign), out_dir, |_| {})?;
    let truth_path = options
        .truth_path
        .clone()
        .unwrap_or_else(|| out_dir.join(drift_recording::TRUTH_DIR).join(TRUTH_FILE));
    if let Some(dir) = truth_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| SimError::io(dir, e))?;
    }
    world.write_truth(&truth_path)?;
    let zero_drift = if options.zero_drift_twin {
        let twin = world.zero_drift_twin();
        let dir = out_dir.join("zero_drift");
        Some(twin.simulate(&twin.campaign(&options.campaign), &dir, |_| {})?)
    } else {
        None
    };
    Ok(WorldRun {
        summary,
        truth_path,
        zero_drift,
    })
}
