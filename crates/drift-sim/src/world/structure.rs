//! The unit's structure beyond the base model, and the bench conditions, drawn per world. Present
//! in null worlds too: it is what a world is, not an undeclared effect.

use crate::thermal::network::{asic, element};
use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// A follower node on each element: a slower part (capsule lid, mount) that the element's
/// temperature coefficient partly follows, `b += c₁·w·(T_lid − T_e)`, `T_lid = L_τ[T_e]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LidNode {
    /// Per axis: the lid's time constant (s).
    pub tau_s: [f64; 3],
    /// Per axis: the weight of the lid in the temperature the bias follows.
    pub weight: [f64; 3],
}

/// An extra conductance of the thermal network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coupling {
    /// Readable node names, e.g. `["element_x", "asic_y"]`.
    pub between: [String; 2],
    /// Node indices (`thermal::network`).
    pub nodes: [usize; 2],
    /// Conductance (W/K).
    pub w_per_k: f64,
}

/// A named auxiliary channel every recording of a world carries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuxChannelSpec {
    /// Name (`/aux/<name>` in the recordings).
    pub name: String,
    /// Physical unit.
    pub unit: String,
    /// Measurement noise, 1σ.
    pub noise: f64,
}

/// The drawn structure and bench conditions of one world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Structure {
    /// Per axis: the capsule gas lags the element by this time constant (s) and the pressure term
    /// follows the gas, `b += c_p·(T_gas − T_e)/298.15 K`; `None`: the gas is at the element's
    /// temperature (the base model).
    pub gas_lag_s: Option<[f64; 3]>,
    /// A lid node per element, or none.
    pub lid: Option<LidNode>,
    /// Extra per-axis couplings in the thermal network (element ↔ other ASICs, ASIC ↔ ASIC).
    pub couplings: Vec<Coupling>,
    /// Temperature-sensor resolution in raw units (200 raw = 1 °C; 1 = the base model's 0.005 °C).
    pub temperature_lsb_raw: f64,
    /// Per-activation, per-axis 1σ relative scatter of the ASIC power in the protocol.
    pub protocol_heating_scatter: f64,
    /// The same in field sessions.
    pub field_heating_scatter: f64,
    /// Largest |chamber air ramp| during a field activation (°C/min).
    pub field_ambient_ramp_c_per_min: f64,
    /// Probability that a field unit is carried to another ambient before a switch-on.
    pub field_carry_probability: f64,
    /// Largest |chamber air ramp| during a protocol activation (°C/min): the chamber's regulation
    /// wandering under the unit's heat; it is back at the set point by the next switch-on.
    pub chamber_wander_c_per_min: f64,
    /// Named auxiliary channels recorded in every activation.
    pub aux_channels: Vec<AuxChannelSpec>,
}

const AXES: [&str; 3] = ["x", "y", "z"];

fn uniform(r: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * r.random::<f64>()
}

/// The named channels every world records (whatever effect reads them).
pub(crate) fn aux_channels() -> Vec<AuxChannelSpec> {
    vec![
        AuxChannelSpec {
            name: super::HUMIDITY.into(),
            unit: "%RH".into(),
            noise: 0.3,
        },
        AuxChannelSpec {
            name: super::AIR_PRESSURE.into(),
            unit: "hPa".into(),
            noise: 0.05,
        },
    ]
}

impl Structure {
    /// The base model's structure and the simulator's default bench (no variation).
    pub fn plain() -> Self {
        Self {
            gas_lag_s: None,
            lid: None,
            couplings: Vec::new(),
            temperature_lsb_raw: 1.0,
            protocol_heating_scatter: 0.005,
            field_heating_scatter: 0.03,
            field_ambient_ramp_c_per_min: 0.0,
            field_carry_probability: 0.0,
            chamber_wander_c_per_min: 0.0,
            aux_channels: aux_channels(),
        }
    }

    /// Draws a structure: each variant is present with probability ½.
    #[allow(clippy::needless_range_loop)] // axis indices name nodes and labels alike
    pub(crate) fn draw(r: &mut ChaCha8Rng) -> Self {
        let mut s = Self::plain();
        if r.random::<bool>() {
            s.gas_lag_s = Some(std::array::from_fn(|_| uniform(r, 20.0, 200.0)));
        }
        if r.random::<bool>() {
            s.lid = Some(LidNode {
                tau_s: std::array::from_fn(|_| uniform(r, 30.0, 300.0)),
                weight: std::array::from_fn(|_| uniform(r, 0.1, 0.4)),
            });
        }
        if r.random::<bool>() {
            // Each element also sits near the other sensors' ASICs: up to a quarter of its own
            // ASIC path (0.006–0.010 W/K), per pair.
            for a in 0..3 {
                for b in 0..3 {
                    if a != b {
                        s.couplings.push(Coupling {
                            between: [format!("element_{}", AXES[a]), format!("asic_{}", AXES[b])],
                            nodes: [element(a), asic(b)],
                            w_per_k: uniform(r, 0.0, 0.002),
                        });
                    }
                }
            }
        }
        if r.random::<bool>() {
            // Neighbouring ASICs share board copper.
            for a in 0..3 {
                let b = (a + 1) % 3;
                s.couplings.push(Coupling {
                    between: [format!("asic_{}", AXES[a]), format!("asic_{}", AXES[b])],
                    nodes: [asic(a), asic(b)],
                    w_per_k: uniform(r, 0.001, 0.005),
                });
            }
        }
        // 0.005, 0.01, 0.02 or 0.0625 °C (a 1/16 °C on-die sensor).
        s.temperature_lsb_raw = [1.0, 2.0, 4.0, 12.5][r.random_range(0..4usize)];
        s.protocol_heating_scatter = uniform(r, 0.005, 0.03);
        s.field_heating_scatter = uniform(r, 0.01, 0.05);
        s.field_ambient_ramp_c_per_min = uniform(r, 0.0, 3.0);
        s.field_carry_probability = uniform(r, 0.0, 0.3);
        if r.random::<bool>() {
            s.chamber_wander_c_per_min = uniform(r, 0.0, 0.3);
        }
        s
    }
}
