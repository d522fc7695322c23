//! Simulates one file: integrates the thermal network through every switch-on and
//! switch-off, evaluates the bias and noise per sample, and streams batches into the
//! recording and its ground-truth sidecar.

use crate::bias::{self, BiasInputs};
use crate::campaign::{Campaign, TruthBias};
use crate::error::SimError;
use crate::faults::{FaultEvent, Injector, FAULTS_METADATA};
use crate::motion;
use crate::rng;
use crate::schedule::{ActivationPlan, FilePlan};
use crate::thermal::network::{asic, capsule, element, NODES};
use crate::thermal::rc::{Discrete, RcNetwork};
use crate::unit::{UnitModel, UnitParams, NOMINAL_SUPPLY_V, REFERENCE_CELSIUS};
use crate::world::runtime::{AuxActivation, Inputs, Runtime};
use drift_recording::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use drift_recording::writer::McapFile;
use drift_recording::{SeriesKind, AUX_RATE_HZ, RAW_PER_CELSIUS};
use rand::rngs::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::Path;

/// Full-scale range of the rate output (°/s); readings saturate here.
pub const RANGE_DPS: f64 = 500.0;
/// Rate output resolution (°/s): the unit outputs 24-bit words with LSB 2⁻¹⁴ °/s, which
/// spans ±512 °/s. The quantisation noise (LSB/√12 ≈ 1.8e-5 °/s) is 350× below the
/// per-sample white noise.
pub const RATE_LSB_DPS: f64 = 1.0 / 16384.0;
const RATE_PER_LSB_INV: f64 = 16384.0;
/// Supply-voltage measurement noise, 1σ (V).
const SUPPLY_NOISE_V: f64 = 0.002;

/// What one file cost.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FileCounts {
    pub samples: u64,
    pub activations: u64,
    pub recording_bytes: u64,
    pub truth_bytes: u64,
}

/// The per-file context that does not change between activations.
pub(crate) struct FileSim<'a> {
    pub campaign: &'a Campaign,
    pub unit: &'a UnitParams,
    pub network: &'a RcNetwork,
    pub step: &'a Discrete,
    pub plan: &'a FilePlan,
    /// A world's extra terms, lags, named channels and sensor resolution; `None` for a campaign.
    pub world: Option<&'a Runtime>,
    /// A world's named channels per activation of the file (empty without a world).
    pub world_aux: &'a [AuxActivation],
}

/// A world's state carried through a file: lag states, and the orientation of the last
/// activation (held through the off-time).
struct WorldState {
    lags: Vec<f64>,
    gravity: [f64; 3],
}

/// Batch buffers, reused across messages.
struct Buffers {
    rate: [Vec<f32>; 3],
    raw: [Vec<i16>; 3],
    truth_bias: [Vec<f32>; 3],
    accel: [Vec<f32>; 3],
    supply: Vec<f32>,
    set_point: Vec<f32>,
    truth_element: [Vec<f32>; 3],
    truth_asic: [Vec<f32>; 3],
    truth_instability: [Vec<f32>; 3],
    /// A world's undeclared effects alone (empty without a world).
    truth_effect: [Vec<f32>; 3],
    /// A world's named channels (empty without a world).
    named: Vec<Vec<f32>>,
}

impl Buffers {
    fn new(batch: usize) -> Self {
        let v = || Vec::with_capacity(batch);
        let a = || Vec::with_capacity(batch / 10 + 1);
        Self {
            rate: [v(), v(), v()],
            raw: [
                Vec::with_capacity(batch),
                Vec::with_capacity(batch),
                Vec::with_capacity(batch),
            ],
            truth_bias: [v(), v(), v()],
            accel: [a(), a(), a()],
            supply: a(),
            set_point: a(),
            truth_element: [a(), a(), a()],
            truth_asic: [a(), a(), a()],
            truth_instability: [a(), a(), a()],
            truth_effect: [a(), a(), a()],
            named: Vec::new(),
        }
    }
    fn clear(&mut self) {
        for v in self
            .rate
            .iter_mut()
            .chain(&mut self.truth_bias)
            .chain(&mut self.accel)
            .chain(&mut self.truth_element)
        {
            v.clear();
        }
        for v in self
            .truth_asic
            .iter_mut()
            .chain(&mut self.truth_instability)
            .chain(&mut self.truth_effect)
        {
            v.clear();
        }
        for v in &mut self.raw {
            v.clear();
        }
        self.supply.clear();
        self.set_point.clear();
        for v in &mut self.named {
            v.clear();
        }
    }
}

fn normal(r: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(r)
}

fn as_refs<T>(v: &[Vec<T>; 3]) -> [&[T]; 3] {
    [&v[0], &v[1], &v[2]]
}

impl FileSim<'_> {
    fn recording_metadata(&self) -> BTreeMap<String, String> {
        let c = self.campaign;
        let entries = [
            ("format_version", schema::FORMAT_VERSION.to_owned()),
            ("unit_id", self.unit.unit_id.clone()),
            ("set_point_celsius", format!("{}", self.plan.set_point_c)),
            ("series_kind", self.plan.kind.as_str().to_owned()),
            ("sample_rate_hz", c.sample_rate_hz.to_string()),
            ("aux_rate_hz", AUX_RATE_HZ.to_string()),
            ("temperature_raw_per_celsius", format!("{RAW_PER_CELSIUS}")),
            ("rate_range_dps", format!("{RANGE_DPS}")),
            ("campaign", c.name.clone()),
            (
                "source",
                concat!("simulated: drift-sim ", env!("CARGO_PKG_VERSION")).to_owned(),
            ),
            (
                "clock",
                "log_time = ns since the campaign start (simulated clock)".to_owned(),
            ),
        ];
        entries
            .into_iter()
            .map(|(k, v)| (k.to_owned(), v))
            .collect()
    }

    fn open_recording(&self, path: &Path) -> Result<McapFile, SimError> {
        let mut f = drift_recording::create_recording(path, self.recording_metadata())?;
        for channel in self.world.map_or(&[][..], |w| &w.aux) {
            f.add_topic(
                &drift_recording::named_aux_topic(&channel.name),
                schema::SCHEMA_SCALAR,
                &[("unit", channel.unit.as_str())],
            )?;
        }
        Ok(f)
    }

    fn open_truth(&self, path: &Path) -> Result<McapFile, SimError> {
        // The sidecar is not a bench recording: lz4 keeps it cheap to write (float truth
        // hardly compresses anyway), so the recording's zstd gets the CPU.
        let mut f = McapFile::create(path, schema::PROFILE_TRUTH, mcap::Compression::Lz4)?;
        f.add_topic(
            schema::TOPIC_TRUTH_BIAS,
            schema::SCHEMA_VECTOR3,
            &[("unit", "deg/s")],
        )?;
        f.add_topic(
            schema::TOPIC_TRUTH_ELEMENT,
            schema::SCHEMA_VECTOR3,
            &[("unit", "degC")],
        )?;
        f.add_topic(
            schema::TOPIC_TRUTH_ASIC,
            schema::SCHEMA_VECTOR3,
            &[("unit", "degC")],
        )?;
        f.add_topic(
            schema::TOPIC_TRUTH_INSTABILITY,
            schema::SCHEMA_VECTOR3,
            &[("unit", "deg/s")],
        )?;
        if self.world.is_some() {
            f.add_topic(
                schema::TOPIC_TRUTH_EFFECT,
                schema::SCHEMA_VECTOR3,
                &[("unit", "deg/s")],
            )?;
        }
        f.add_topic(schema::TOPIC_POWER, schema::SCHEMA_POWER, &[])?;
        f.metadata(schema::METADATA_RECORDING, self.recording_metadata())?;
        Ok(f)
    }

    /// Runs the whole file. `progress` receives the number of samples just done, after each
    /// block of samples; when it breaks, the run stops with [`SimError::Interrupted`].
    pub fn run(
        &self,
        recording: &Path,
        truth: &Path,
        progress: &mut dyn FnMut(u64) -> ControlFlow<()>,
    ) -> Result<FileCounts, SimError> {
        let c = self.campaign;
        let mut rec = self.open_recording(recording)?;
        let mut tru = self.open_truth(truth)?;
        let mut r = rng::stream(
            c.seed,
            &[
                rng::tag("noise"),
                u64::from(self.plan.unit_index),
                u64::from(self.plan.file_index),
            ],
        );
        let sp = self.plan.set_point_c;
        // The file starts with the unit soaked at the set point (the chamber settled).
        let mut x = [sp; NODES];
        let mut instability = [0.0; 3];
        for (a, v) in instability.iter_mut().enumerate() {
            *v = self.unit.axes[a].instability_sigma_dps * c.noise_scale * normal(&mut r);
        }
        let mut clock_ms = self.plan.start_ms;
        let mut counts = FileCounts::default();
        let mut buffers = Buffers::new((c.sample_rate_hz / 10) as usize);
        let mut world = self.world.map(|w| {
            buffers.named = vec![Vec::new(); w.aux.len()];
            let first = self.plan.activations.first();
            let gravity = first.map_or(crate::schedule::Z_UP, |a| a.gravity_body);
            let mut aux = vec![0.0; w.aux.len()];
            if let Some(a) = self.world_aux.first() {
                a.at(0.0, &mut aux);
            }
            let lags = w.initial_lags(&Inputs {
                temps: &x,
                on_asic: &[0.0; 3],
                gravity,
                supply_v: NOMINAL_SUPPLY_V,
                aux: &aux,
            });
            WorldState { lags, gravity }
        });
        let mut fault_log: Vec<FaultEvent> = Vec::new();
        for (index, act) in self.plan.activations.iter().enumerate() {
            // A stream of their own: switching faults on changes no other draw.
            let faults = if c.faults.any() {
                let mut fr = rng::stream(
                    c.seed,
                    &[
                        rng::tag("faults"),
                        u64::from(self.plan.unit_index),
                        u64::from(self.plan.file_index),
                        index as u64,
                    ],
                );
                c.faults.draw(
                    &mut fr,
                    (act.series, act.repeat, act.activation),
                    act.samples,
                    c.sample_rate_hz,
                )
            } else {
                Vec::new()
            };
            // Off-time: unpowered, ambient held: the exact solution, however long.
            let off_s = act.off_before_ms as f64 / 1000.0;
            if let (Some(w), Some(state)) = (self.world, world.as_mut()) {
                let mut aux = vec![0.0; w.aux.len()];
                if let Some(a) = self.world_aux.get(index) {
                    a.at(0.0, &mut aux);
                }
                w.off_time(
                    self.network,
                    &x,
                    act.ambient_off_c,
                    off_s,
                    state.gravity,
                    &aux,
                    &mut state.lags,
                );
            }
            let cooled = self
                .network
                .advance(&x, &[0.0; NODES], act.ambient_off_c, off_s);
            x.copy_from_slice(&cooled);
            for (a, v) in instability.iter_mut().enumerate() {
                let axis = &self.unit.axes[a];
                let phi = (-off_s / axis.instability_tau_s).exp();
                *v = phi * *v
                    + axis.instability_sigma_dps
                        * c.noise_scale
                        * (1.0 - phi * phi).sqrt()
                        * normal(&mut r);
            }
            clock_ms += act.off_before_ms;
            self.activation(
                act,
                &faults,
                clock_ms,
                &mut x,
                &mut instability,
                (world.as_mut(), self.world_aux.get(index)),
                &mut r,
                &mut rec,
                &mut tru,
                &mut buffers,
                progress,
            )?;
            fault_log.extend(faults);
            clock_ms += u64::from(act.samples) * 1000 / u64::from(c.sample_rate_hz);
            counts.samples += u64::from(act.samples);
            counts.activations += 1;
        }
        if c.faults.any() {
            // Ground truth only: where each fault was injected, for evaluation code.
            let events = serde_json::to_string(&fault_log).map_err(|e| SimError::Json {
                path: truth.to_path_buf(),
                source: e,
            })?;
            tru.metadata(
                FAULTS_METADATA,
                BTreeMap::from([("events".to_owned(), events)]),
            )?;
        }
        counts.recording_bytes = rec.finish()?;
        counts.truth_bytes = tru.finish()?;
        Ok(counts)
    }

    fn event(&self, act: &ActivationPlan, powered: bool, ambient_c: f64) -> PowerEvent {
        // A chamber bench logs its set point, not the air's regulation cycle around it; in the
        // field the label is the ambient the user saw.
        let labelled_c = if self.plan.kind == SeriesKind::Protocol {
            self.plan.set_point_c
        } else {
            ambient_c
        };
        PowerEvent {
            powered,
            series_kind: self.plan.kind.as_str().to_owned(),
            series: act.series,
            repeat: act.repeat,
            activation: act.activation,
            interval_min: act.interval_min.unwrap_or(f64::NAN),
            off_before_s: act.off_before_ms as f64 / 1000.0,
            set_point_celsius: labelled_c,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn activation(
        &self,
        act: &ActivationPlan,
        faults: &[FaultEvent],
        on_ms: u64,
        x: &mut [f64; NODES],
        instability: &mut [f64; 3],
        (mut world, world_aux): (Option<&mut WorldState>, Option<&AuxActivation>),
        r: &mut ChaCha8Rng,
        rec: &mut McapFile,
        tru: &mut McapFile,
        buf: &mut Buffers,
        progress: &mut dyn FnMut(u64) -> ControlFlow<()>,
    ) -> Result<(), SimError> {
        let c = self.campaign;
        let unit = self.unit;
        let noise = c.noise_scale;
        let fs = c.sample_rate_hz;
        let h = 1.0 / f64::from(fs);
        let period_ns = 1_000_000_000 / u64::from(fs);
        let on_ns = on_ms * 1_000_000;
        let batch = fs / 10;
        let aux_every = fs / AUX_RATE_HZ;

        let on_event = self.event(act, true, act.ambient_on_c);
        rec.power(&on_event, on_ns)?;
        tru.power(&on_event, on_ns)?;

        let jitter: [f64; 3] =
            std::array::from_fn(|a| unit.axes[a].turn_on_sigma_dps * noise * normal(r));
        let white: [f64; 3] = std::array::from_fn(|a| {
            unit.axes[a].white_noise_dps_per_rt_hz * f64::from(fs).sqrt() * noise
        });
        let gm_step_s = f64::from(aux_every) * h;
        let gm_phi: [f64; 3] =
            std::array::from_fn(|a| (-gm_step_s / unit.axes[a].instability_tau_s).exp());
        let gm_q: [f64; 3] = std::array::from_fn(|a| {
            unit.axes[a].instability_sigma_dps * noise * (1.0 - gm_phi[a] * gm_phi[a]).sqrt()
        });
        let temp_noise: [f64; 3] =
            std::array::from_fn(|a| unit.axes[a].temperature_noise_raw * noise);
        // The node whose temperature the bias follows: the element, or for a unit the paper's
        // model represents exactly, the sensor's own site (decided once, not per sample).
        let sensor_site = unit.model == UnitModel::PaperExact;
        let biasing = |a: usize| {
            if sensor_site {
                asic(a)
            } else {
                element(a)
            }
        };
        let capsule_site = |a: usize| {
            if sensor_site {
                asic(a)
            } else {
                capsule(a)
            }
        };
        let lag_on = unit
            .axes
            .iter()
            .any(|a| a.thermal_lag_dps_per_c_per_s != 0.0);
        let nonlinear = unit.asic_power_per_c != 0.0;
        // The chamber channel logs what the chamber was told: a bench's set point, not the
        // regulation cycle of its air; in the field, the ramps the environment went through.
        let protocol_bench = self.plan.kind == SeriesKind::Protocol;
        let set_point_c = self.plan.set_point_c as f32;
        let every_sample_truth = c.truth_bias == TruthBias::EverySample;
        let ramp = act.ambient_ramp_c_per_s;
        let days_base_s = on_ms as f64 / 1000.0;

        let base_power = unit
            .thermal
            .power_w(act.heating_scale, act.supply_v / NOMINAL_SUPPLY_V);
        let mut power = base_power;
        let mut forcing = [0.0; NODES];
        self.step
            .forcing(&power, act.ambient_on_c + 0.5 * h * ramp, &mut forcing);
        let mut next = [0.0; NODES];
        let mut accel_true = act.gravity_body;
        let mut rotation = 0usize;

        let grid_s = f64::from(aux_every) * h;
        let mut inject = (!faults.is_empty()).then(|| Injector::new(faults));
        // A world's extra bias, evaluated on the 10 ms grid and interpolated like the
        // temperatures; its named channels' true values at the grid point and the next.
        let runtime = self.world.filter(|_| world.is_some());
        let on_asic: [f64; 3] = std::array::from_fn(|a| x[asic(a)]);
        let n_aux = runtime.map_or(0, |w| w.aux.len());
        let (mut aux_now, mut aux_next) = (vec![0.0; n_aux], vec![0.0; n_aux]);
        let (mut extra_now, mut extra_next) = ([0.0; 3], [0.0; 3]);
        let mut effect_next = [0.0; 3];
        let lsb_raw = runtime.map_or(1.0, |w| w.temperature_lsb_raw);
        if let (Some(w), Some(state)) = (runtime, world.as_deref_mut()) {
            state.gravity = accel_true;
            if let Some(a) = world_aux {
                a.at(0.0, &mut aux_next);
            }
            let inputs = Inputs {
                temps: x,
                on_asic: &on_asic,
                gravity: accel_true,
                supply_v: act.supply_v,
                aux: &aux_next,
            };
            w.extra(&inputs, &state.lags, &mut extra_next, &mut effect_next);
        }
        for i in 0..act.samples {
            let t = f64::from(i) * h;
            let body_dps = motion::rate_from(&act.motion, &mut rotation, i);
            let ambient = act.ambient_on_c + ramp * t;
            let phase = i % aux_every;
            if phase == 0 {
                // Advance the thermal state one 10-ms grid step, exactly for inputs held
                // over the step; samples in between are interpolated linearly. The fastest
                // thermal mode has a time constant of ~8 s, so the interpolation error is
                // below 1e-6 °C (h²/8 · |T̈|), far below the sensor's 0.005 °C step.
                if nonlinear {
                    for a in 0..3 {
                        let growth = 1.0 + unit.asic_power_per_c * (x[asic(a)] - REFERENCE_CELSIUS);
                        power[asic(a)] = base_power[asic(a)] * growth.max(0.0);
                    }
                }
                if nonlinear || ramp != 0.0 {
                    self.step
                        .forcing(&power, ambient + 0.5 * grid_s * ramp, &mut forcing);
                }
                self.step.step(x, &forcing, &mut next);
                if let (Some(w), Some(state)) = (runtime, world.as_deref_mut()) {
                    std::mem::swap(&mut aux_now, &mut aux_next);
                    if let Some(a) = world_aux {
                        a.at(t + grid_s, &mut aux_next);
                    }
                    let at = |temps, aux| Inputs {
                        temps,
                        on_asic: &on_asic,
                        gravity: accel_true,
                        supply_v: act.supply_v,
                        aux,
                    };
                    w.step_lags(
                        &at(x, &aux_now),
                        &at(&next, &aux_next),
                        grid_s,
                        &mut state.lags,
                    );
                    extra_now = extra_next;
                    let effect_now = effect_next;
                    w.extra(
                        &at(&next, &aux_next),
                        &state.lags,
                        &mut extra_next,
                        &mut effect_next,
                    );
                    for a in 0..3 {
                        let rate = if w.rate_is_effect {
                            unit.axes[a].thermal_lag_dps_per_c_per_s
                                * (next[biasing(a)] - x[biasing(a)])
                                / grid_s
                        } else {
                            0.0
                        };
                        buf.truth_effect[a].push((effect_now[a] + rate) as f32);
                    }
                    for (k, channel) in w.aux.iter().enumerate() {
                        let v = aux_now[k] + channel.noise * noise * normal(r);
                        buf.named[k].push(v as f32);
                    }
                }
                // Bias instability is updated on the same grid: its correlation time is
                // ≥ 100 s, so holding it for 10 ms changes nothing measurable.
                for a in 0..3 {
                    instability[a] = gm_phi[a] * instability[a] + gm_q[a] * normal(r);
                }
                for a in 0..3 {
                    let g = accel_true[a]
                        + unit.accel.bias_g[a]
                        + unit.accel.noise_g * noise * normal(r);
                    buf.accel[a].push(g as f32);
                    buf.truth_element[a].push(x[biasing(a)] as f32);
                    buf.truth_asic[a].push(x[asic(a)] as f32);
                    buf.truth_instability[a].push(instability[a] as f32);
                }
                if !act.motion.is_empty() {
                    accel_true = motion::turn_gravity(accel_true, body_dps, grid_s);
                }
                buf.supply
                    .push((act.supply_v + SUPPLY_NOISE_V * noise * normal(r)) as f32);
                buf.set_point.push(if protocol_bench {
                    set_point_c
                } else {
                    ambient as f32
                });
            }
            let frac = f64::from(phase) / f64::from(aux_every);
            for a in 0..3 {
                let axis = &unit.axes[a];
                let (e, s, k) = (biasing(a), asic(a), capsule_site(a));
                let element_c = x[e] + frac * (next[e] - x[e]);
                let capsule_c = x[k] + frac * (next[k] - x[k]);
                let asic_c = x[s] + frac * (next[s] - x[s]);
                let inputs = BiasInputs {
                    element_c,
                    capsule_c,
                    // The exact mean heating rate over the grid step.
                    element_rate_c_per_s: if lag_on {
                        (next[e] - x[e]) / grid_s
                    } else {
                        0.0
                    },
                    accel_g: accel_true,
                    supply_v: act.supply_v,
                    campaign_s: days_base_s + t,
                };
                let mut systematic = bias::systematic_dps(axis, &inputs) + jitter[a];
                if runtime.is_some() {
                    systematic += extra_now[a] + frac * (extra_next[a] - extra_now[a]);
                }
                let rate = (systematic + instability[a] + white[a] * normal(r) + body_dps[a])
                    .clamp(-RANGE_DPS, RANGE_DPS);
                let mut raw = (asic_c + axis.temperature_offset_c) * RAW_PER_CELSIUS
                    + temp_noise[a] * normal(r);
                if lsb_raw != 1.0 {
                    // A coarser sensor: its reading is a multiple of its LSB.
                    raw = (raw / lsb_raw).round() * lsb_raw;
                }
                // The unit outputs 24-bit words: quantise to the output LSB.
                let counts = rate * RATE_PER_LSB_INV;
                let counts = (counts + 0.5f64.copysign(counts)) as i32;
                buf.rate[a].push((f64::from(counts) * RATE_LSB_DPS) as f32);
                // Round half away from zero; `as` saturates at the i16 limits (the sensor's
                // range). Cheaper than f64::round, which is a libm call on baseline x86-64.
                let reading = (raw + 0.5f64.copysign(raw)) as i16;
                buf.raw[a].push(match inject.as_mut() {
                    Some(inject) => inject.apply(a, i, reading),
                    None => reading,
                });
                if every_sample_truth || phase == 0 {
                    buf.truth_bias[a].push(systematic as f32);
                }
            }
            if phase + 1 == aux_every {
                *x = next;
            }

            if (i + 1) % batch == 0 || i + 1 == act.samples {
                let first = i + 1 - buf.rate[0].len() as u32;
                let log_ns = on_ns + u64::from(first) * period_ns;
                Vector3Batch::encode(first, fs, as_refs(&buf.rate), &mut rec.enc);
                rec.write_encoded(schema::TOPIC_RATE, log_ns)?;
                RawTemperatureBatch::encode(first, fs, as_refs(&buf.raw), &mut rec.enc);
                rec.write_encoded(schema::TOPIC_TEMPERATURE_RAW, log_ns)?;
                let aux_first = first.div_ceil(aux_every);
                Vector3Batch::encode(aux_first, AUX_RATE_HZ, as_refs(&buf.accel), &mut rec.enc);
                rec.write_encoded(schema::TOPIC_ACCEL, log_ns)?;
                ScalarBatch::encode(aux_first, AUX_RATE_HZ, &buf.supply, &mut rec.enc);
                rec.write_encoded(schema::TOPIC_SUPPLY, log_ns)?;
                ScalarBatch::encode(aux_first, AUX_RATE_HZ, &buf.set_point, &mut rec.enc);
                rec.write_encoded(schema::TOPIC_SET_POINT, log_ns)?;
                for (k, channel) in runtime.map_or(&[][..], |w| &w.aux).iter().enumerate() {
                    ScalarBatch::encode(aux_first, AUX_RATE_HZ, &buf.named[k], &mut rec.enc);
                    rec.write_encoded(&drift_recording::named_aux_topic(&channel.name), log_ns)?;
                }
                let (bias_first, bias_rate) = if every_sample_truth {
                    (first, fs)
                } else {
                    (aux_first, AUX_RATE_HZ)
                };
                Vector3Batch::encode(
                    bias_first,
                    bias_rate,
                    as_refs(&buf.truth_bias),
                    &mut tru.enc,
                );
                tru.write_encoded(schema::TOPIC_TRUTH_BIAS, log_ns)?;
                Vector3Batch::encode(
                    aux_first,
                    AUX_RATE_HZ,
                    as_refs(&buf.truth_element),
                    &mut tru.enc,
                );
                tru.write_encoded(schema::TOPIC_TRUTH_ELEMENT, log_ns)?;
                Vector3Batch::encode(
                    aux_first,
                    AUX_RATE_HZ,
                    as_refs(&buf.truth_asic),
                    &mut tru.enc,
                );
                tru.write_encoded(schema::TOPIC_TRUTH_ASIC, log_ns)?;
                Vector3Batch::encode(
                    aux_first,
                    AUX_RATE_HZ,
                    as_refs(&buf.truth_instability),
                    &mut tru.enc,
                );
                tru.write_encoded(schema::TOPIC_TRUTH_INSTABILITY, log_ns)?;
                if runtime.is_some() {
                    Vector3Batch::encode(
                        aux_first,
                        AUX_RATE_HZ,
                        as_refs(&buf.truth_effect),
                        &mut tru.enc,
                    );
                    tru.write_encoded(schema::TOPIC_TRUTH_EFFECT, log_ns)?;
                }
                if progress(buf.rate[0].len() as u64).is_break() {
                    return Err(SimError::Interrupted);
                }
                buf.clear();
            }
        }
        let end_ambient = act.ambient_on_c + ramp * f64::from(act.samples) * h;
        let off_event = self.event(act, false, end_ambient);
        let off_ns = on_ns + u64::from(act.samples) * period_ns;
        rec.power(&off_event, off_ns)?;
        tru.power(&off_event, off_ns)?;
        Ok(())
    }
}
