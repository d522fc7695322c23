//! The gyro unit's thermal network: which nodes exist and how they are connected.
//!
//! ```text
//!             P_supply                      P_asic,x (and y, z)
//!                ↓                               ↓
//!   ambient ── housing ──── board ──── ASIC_x (temperature sensor) ── element_x (in capsule)
//!     g_ha       │ │ g_bh          g_ab                          g_ae        │   │
//!                │ └─────────────────────────── g_eh ────────────────────────┘   │ g_ec
//!                └───────────────── g_ch ──────────────────────────────── capsule_x (glass + gas)
//! ```
//!
//! The supply on the board and each sensor's ASIC dissipate only while powered. The
//! temperature sensor sits on the ASIC; the sensing element inside its glass capsule is
//! heated through the ASIC and lags it; the capsule (its glass and the gas it holds) is heated
//! by the element and lags it again. The housing carries the slow mode that decides how much
//! heat is left after a short off-time.

use super::rc::RcNetwork;
use serde::{Deserialize, Serialize};

/// Node index of the housing.
pub const HOUSING: usize = 0;
/// Node index of the board carrying the secondary power supply.
pub const BOARD: usize = 1;
/// Node index of the ASIC of axis `a` (0 = X, 1 = Y, 2 = Z); the temperature sensor is here.
pub const fn asic(a: usize) -> usize {
    2 + a
}
/// Node index of the MEMS element (inside its glass capsule) of axis `a`.
pub const fn element(a: usize) -> usize {
    5 + a
}
/// Node index of the glass capsule (and the gas it holds) around element `a`.
pub const fn capsule(a: usize) -> usize {
    8 + a
}
/// Number of nodes.
pub const NODES: usize = 11;

/// Heat capacities, conductances and heat sources of one unit (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThermalParams {
    /// Housing heat capacity (J/K).
    pub housing_j_per_k: f64,
    /// Board + supply heat capacity (J/K).
    pub board_j_per_k: f64,
    /// ASIC + package heat capacity per axis (J/K).
    pub asic_j_per_k: [f64; 3],
    /// Element + capsule heat capacity per axis (J/K).
    pub element_j_per_k: [f64; 3],
    /// Housing → ambient (chamber air) conductance (W/K).
    pub housing_to_ambient_w_per_k: f64,
    /// Board → housing conductance (W/K).
    pub board_to_housing_w_per_k: f64,
    /// ASIC → board conductance per axis (W/K).
    pub asic_to_board_w_per_k: [f64; 3],
    /// ASIC → element conductance per axis (W/K).
    pub asic_to_element_w_per_k: [f64; 3],
    /// Element → housing conductance per axis (W/K).
    pub element_to_housing_w_per_k: [f64; 3],
    /// Glass capsule + gas heat capacity per axis (J/K).
    pub capsule_j_per_k: [f64; 3],
    /// Element → capsule conductance per axis, through the gas (W/K).
    pub element_to_capsule_w_per_k: [f64; 3],
    /// Capsule → housing conductance per axis, through its mounting (W/K).
    pub capsule_to_housing_w_per_k: [f64; 3],
    /// Element `i` → ASIC `j ≠ i` conductance (W/K); zero unless the hidden cross-axis effect is on.
    pub cross_axis_w_per_k: f64,
    /// Supply dissipation at nominal voltage while powered (W).
    pub supply_power_w: f64,
    /// ASIC dissipation per axis while powered (W).
    pub asic_power_w: [f64; 3],
    /// Relative change of supply dissipation per relative change of supply voltage
    /// (a linear regulator dissipates (V_in − V_out)·I, so this is > 1).
    pub supply_power_per_relative_volt: f64,
}

impl ThermalParams {
    /// Builds the solvable network.
    pub fn network(&self) -> Result<RcNetwork, String> {
        self.network_with(&[])
    }

    /// Builds the solvable network with extra conductances `(node, node, W/K)` added after the
    /// unit's own links (node indices as [`asic`], [`element`], [`HOUSING`], [`BOARD`]).
    pub fn network_with(&self, extra_links: &[(usize, usize, f64)]) -> Result<RcNetwork, String> {
        let mut capacity = [0.0; NODES];
        let mut between = [0.0; NODES * NODES];
        let mut to_ambient = [0.0; NODES];
        let mut link = |a: usize, b: usize, g: f64| {
            between[a * NODES + b] += g;
            between[b * NODES + a] += g;
        };
        capacity[HOUSING] = self.housing_j_per_k;
        capacity[BOARD] = self.board_j_per_k;
        to_ambient[HOUSING] = self.housing_to_ambient_w_per_k;
        link(BOARD, HOUSING, self.board_to_housing_w_per_k);
        for a in 0..3 {
            capacity[asic(a)] = self.asic_j_per_k[a];
            capacity[element(a)] = self.element_j_per_k[a];
            link(asic(a), BOARD, self.asic_to_board_w_per_k[a]);
            link(asic(a), element(a), self.asic_to_element_w_per_k[a]);
            link(element(a), HOUSING, self.element_to_housing_w_per_k[a]);
            capacity[capsule(a)] = self.capsule_j_per_k[a];
            link(element(a), capsule(a), self.element_to_capsule_w_per_k[a]);
            link(capsule(a), HOUSING, self.capsule_to_housing_w_per_k[a]);
            for b in 0..3 {
                if b != a && self.cross_axis_w_per_k > 0.0 {
                    link(element(a), asic(b), self.cross_axis_w_per_k);
                }
            }
        }
        for &(a, b, g) in extra_links {
            if a >= NODES || b >= NODES || a == b {
                return Err(format!(
                    "extra link {a} ↔ {b}: nodes must differ and be < {NODES}"
                ));
            }
            link(a, b, g);
        }
        RcNetwork::new(&capacity, &between, &to_ambient)
    }

    /// Heat sources (W) while powered, with per-axis heating scale factors and a supply
    /// voltage relative to nominal (1.0 = nominal).
    pub fn power_w(&self, asic_scale: [f64; 3], relative_voltage: f64) -> [f64; NODES] {
        let mut p = [0.0; NODES];
        p[BOARD] = self.supply_power_w
            * (1.0 + self.supply_power_per_relative_volt * (relative_voltage - 1.0)).max(0.0);
        for a in 0..3 {
            p[asic(a)] = self.asic_power_w[a] * asic_scale[a];
        }
        p
    }
}
