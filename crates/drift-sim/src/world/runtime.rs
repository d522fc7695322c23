//! What the engine needs of a world while it integrates: the extra bias terms, the first-order
//! lag states they and the structure read, the named auxiliary channels and the temperature
//! sensor's quantisation. Built from a [`super::World`]; the engine only calls it when a world is
//! being simulated.

use super::effects::{EffectForm, Source, Term};
use super::structure::Structure;
use crate::bias::relative_pressure;
use crate::thermal::network::{asic, element, NODES};
use crate::thermal::rc::RcNetwork;
use crate::unit::{UnitParams, NOMINAL_SUPPLY_V, REFERENCE_CELSIUS};

/// What a term or a lag reads.
#[derive(Debug, Clone, Copy)]
enum Input {
    Accel(usize),
    Supply,
    Aux(usize, f64),
    /// A node's temperature − 25 °C.
    Node(usize),
}

#[derive(Debug, Clone)]
struct RuntimeTerm {
    axis: usize,
    input: Input,
    form: EffectForm,
    rise_axis: Option<usize>,
    lag: Option<usize>,
    k: f64,
}

#[derive(Debug, Clone, Copy)]
struct Lag {
    input: Input,
    tau_s: f64,
}

/// A named auxiliary channel the world records.
#[derive(Debug, Clone)]
pub(crate) struct AuxSpec {
    pub name: String,
    pub unit: String,
    /// Measurement noise, 1σ.
    pub noise: f64,
}

/// The named channels' true values in one activation: `start + ramp · t`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AuxActivation {
    pub start: Vec<f64>,
    pub ramp_per_s: Vec<f64>,
}

impl AuxActivation {
    pub fn at(&self, t: f64, out: &mut [f64]) {
        for ((o, s), r) in out.iter_mut().zip(&self.start).zip(&self.ramp_per_s) {
            *o = s + r * t;
        }
    }
}

/// The instantaneous inputs of the world's terms.
pub(crate) struct Inputs<'a> {
    pub temps: &'a [f64; NODES],
    /// Sensor-site temperatures at switch-on.
    pub on_asic: &'a [f64; 3],
    pub gravity: [f64; 3],
    pub supply_v: f64,
    pub aux: &'a [f64],
}

/// A world, ready for the engine.
#[derive(Debug, Clone)]
pub(crate) struct Runtime {
    terms: Vec<RuntimeTerm>,
    lags: Vec<Lag>,
    /// Per axis: (lag index of the capsule gas, pressure coefficient / 298.15 K).
    gas: [Option<(usize, f64)>; 3],
    /// Per axis: (lag index of the lid node, tempco × weight).
    lid: [Option<(usize, f64)>; 3],
    pub temperature_lsb_raw: f64,
    pub aux: Vec<AuxSpec>,
    /// The unit's element-rate sensitivity is an undeclared effect's (the `temperature_rate`
    /// family), not the structure's: it belongs in the effect's truth.
    pub rate_is_effect: bool,
    pub links: Vec<(usize, usize, f64)>,
    any_temperature_lag: bool,
}

impl Runtime {
    pub fn new(unit: &UnitParams, structure: &Structure, terms: &[Term]) -> Self {
        let aux: Vec<AuxSpec> = structure
            .aux_channels
            .iter()
            .map(|c| AuxSpec {
                name: c.name.clone(),
                unit: c.unit.clone(),
                noise: c.noise,
            })
            .collect();
        let input = |s: &Source| match s {
            Source::Accelerometer { component } => Input::Accel(*component),
            Source::SupplyVoltage => Input::Supply,
            Source::Aux { name, reference } => Input::Aux(
                aux.iter().position(|c| &c.name == name).unwrap_or(0),
                *reference,
            ),
            Source::ElementTemperature { axis } => Input::Node(element(*axis)),
            Source::SensorTemperature { axis } => Input::Node(asic(*axis)),
        };
        let mut lags = Vec::new();
        let mut gas = [None; 3];
        let mut lid = [None; 3];
        // The pressure term's slope per °C: c_p / (25 + 273.15) K.
        let per_c = relative_pressure(REFERENCE_CELSIUS + 1.0) - 1.0;
        for a in 0..3 {
            if let Some(tau) = structure.gas_lag_s {
                lags.push(Lag {
                    input: Input::Node(element(a)),
                    tau_s: tau[a],
                });
                gas[a] = Some((lags.len() - 1, unit.axes[a].pressure_dps * per_c));
            }
            if let Some(l) = &structure.lid {
                lags.push(Lag {
                    input: Input::Node(element(a)),
                    tau_s: l.tau_s[a],
                });
                lid[a] = Some((lags.len() - 1, unit.axes[a].tempco_dps_per_c * l.weight[a]));
            }
        }
        let mut runtime_terms = Vec::new();
        for t in terms {
            let input = input(&t.source);
            let lag = t
                .tau_s
                .filter(|_| t.form == EffectForm::Lagged)
                .map(|tau_s| {
                    lags.push(Lag { input, tau_s });
                    lags.len() - 1
                });
            runtime_terms.push(RuntimeTerm {
                axis: t.axis,
                input,
                form: t.form,
                rise_axis: t.rise_axis,
                lag,
                k: t.coefficient,
            });
        }
        let any_temperature_lag = lags.iter().any(|l| matches!(l.input, Input::Node(_)));
        let links = structure
            .couplings
            .iter()
            .map(|c| (c.nodes[0], c.nodes[1], c.w_per_k))
            .collect();
        Self {
            terms: runtime_terms,
            lags,
            gas,
            lid,
            temperature_lsb_raw: structure.temperature_lsb_raw,
            aux,
            rate_is_effect: false,
            links,
            any_temperature_lag,
        }
    }

    fn value(input: Input, x: &Inputs) -> f64 {
        match input {
            Input::Accel(c) => x.gravity[c],
            Input::Supply => x.supply_v - NOMINAL_SUPPLY_V,
            Input::Aux(i, reference) => x.aux[i] - reference,
            Input::Node(n) => x.temps[n] - REFERENCE_CELSIUS,
        }
    }

    /// Lag states in equilibrium with the inputs.
    pub fn initial_lags(&self, x: &Inputs) -> Vec<f64> {
        self.lags.iter().map(|l| Self::value(l.input, x)).collect()
    }

    /// Advances the lag states over `h_s` with inputs varying linearly from `x0` to `x1` (exact
    /// for that input).
    pub fn step_lags(&self, x0: &Inputs, x1: &Inputs, h_s: f64, lags: &mut [f64]) {
        for (y, l) in lags.iter_mut().zip(&self.lags) {
            let (u0, u1) = (Self::value(l.input, x0), Self::value(l.input, x1));
            let phi = (-h_s / l.tau_s).exp();
            let slope_tau = (u1 - u0) / h_s * l.tau_s;
            *y = u1 - slope_tau + (*y - u0 + slope_tau) * phi;
        }
    }

    /// Advances the lag states through an off-time: the unit unpowered at `ambient_c`, the
    /// accelerometer at `gravity`, the supply at nominal (no deviation), the named channels at
    /// `aux`. Temperatures are followed in steps of ≤ 2 s; `temps` is the state at switch-off.
    #[allow(clippy::too_many_arguments)]
    pub fn off_time(
        &self,
        network: &RcNetwork,
        temps: &[f64; NODES],
        ambient_c: f64,
        off_s: f64,
        gravity: [f64; 3],
        aux: &[f64],
        lags: &mut [f64],
    ) {
        if self.lags.is_empty() || off_s <= 0.0 {
            return;
        }
        const NO_RISE: [f64; 3] = [0.0; 3];
        fn inputs<'a>(temps: &'a [f64; NODES], gravity: [f64; 3], aux: &'a [f64]) -> Inputs<'a> {
            Inputs {
                temps,
                on_asic: &NO_RISE,
                gravity,
                supply_v: NOMINAL_SUPPLY_V,
                aux,
            }
        }
        if !self.any_temperature_lag {
            let x = inputs(temps, gravity, aux);
            self.step_lags(&x, &x, off_s, lags);
            return;
        }
        let n = (off_s / 2.0).ceil().max(1.0);
        let h = off_s / n;
        let step = network.discretise(h);
        let mut forcing = [0.0; NODES];
        step.forcing(&[0.0; NODES], ambient_c, &mut forcing);
        let mut x = *temps;
        let mut next = [0.0; NODES];
        for _ in 0..n as u64 {
            step.step(&x, &forcing, &mut next);
            self.step_lags(
                &inputs(&x, gravity, aux),
                &inputs(&next, gravity, aux),
                h,
                lags,
            );
            x = next;
        }
    }

    /// The world's extra bias per axis (°/s) at one instant.
    /// `effect` receives the undeclared effects' part alone (the structure's lags left out): what
    /// an oracle knows.
    pub fn extra(&self, x: &Inputs, lags: &[f64], out: &mut [f64; 3], effect: &mut [f64; 3]) {
        *out = [0.0; 3];
        *effect = [0.0; 3];
        for (a, o) in out.iter_mut().enumerate() {
            let te = x.temps[element(a)];
            if let Some((l, k)) = self.gas[a] {
                *o += k * (lags[l] - (te - REFERENCE_CELSIUS));
            }
            if let Some((l, k)) = self.lid[a] {
                *o += k * (lags[l] - (te - REFERENCE_CELSIUS));
            }
        }
        let rise = |b: usize| x.temps[asic(b)] - x.on_asic[b];
        for t in &self.terms {
            let u = Self::value(t.input, x);
            let feature = match t.form {
                EffectForm::Offset => u,
                EffectForm::TimesElementDeviation => {
                    u * (x.temps[element(t.axis)] - REFERENCE_CELSIUS)
                }
                EffectForm::TimesRise | EffectForm::OnOtherAxis => match t.rise_axis {
                    Some(b) => u * rise(b),
                    None => u,
                },
                EffectForm::Lagged => t.lag.map_or(u, |l| lags[l]),
                EffectForm::Quadratic => u * u,
            };
            out[t.axis] += t.k * feature;
            effect[t.axis] += t.k * feature;
        }
    }
}
