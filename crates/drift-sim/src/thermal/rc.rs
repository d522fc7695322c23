//! A linear lumped-capacitance (RC) thermal network, solved exactly.
//!
//! Node `i` has heat capacity `Cᵢ` (J/K), conductances `gᵢⱼ` (W/K) to other nodes, a
//! conductance `gᵢₐ` to ambient, and dissipates `Pᵢ` (W):
//!
//! ```text
//! Cᵢ dTᵢ/dt = Σⱼ gᵢⱼ (Tⱼ − Tᵢ) + gᵢₐ (T_amb − Tᵢ) + Pᵢ      ⇔   C Ṫ = −L T + gₐ T_amb + P
//! ```
//!
//! `L` is symmetric positive definite when at least one node touches ambient, so
//! `M = C^{-1/2} L C^{-1/2} = Q Λ Qᵀ` has real positive eigenvalues λₖ (1/s) and the
//! solution is a sum of decaying exponentials. Stepping uses the exact zero-order-hold
//! discretisation `T(t+h) = Φ(h) T(t) + Γ(h) u` with `Φ(h) = e^{Ah}`, so on/off switching
//! at step boundaries is exact and the scheme is stable for any step.

use super::eigen::symmetric_eigen;

/// A thermal network in modal form, ready to be stepped exactly.
#[derive(Debug, Clone)]
pub struct RcNetwork {
    n: usize,
    capacity: Vec<f64>,
    to_ambient: Vec<f64>,
    /// `L` (W/K), row-major.
    laplacian: Vec<f64>,
    /// Modal decay rates λₖ (1/s), ascending.
    rates: Vec<f64>,
    /// `S = C^{-1/2} Q`: modal → nodal.
    from_modes: Vec<f64>,
    /// `S⁻¹ = Qᵀ C^{1/2}`: nodal → modal.
    to_modes: Vec<f64>,
}

/// The exact one-step map of a network for a fixed step `h`.
#[derive(Debug, Clone)]
pub struct Discrete {
    n: usize,
    /// `Φ(h)`, row-major `n × n`.
    phi: Vec<f64>,
    /// `Γ_P(h)`: response to a held power vector (K per W), row-major `n × n`.
    gamma_power: Vec<f64>,
    /// `Γ_amb(h)`: response to a held ambient temperature (dimensionless), length `n`.
    gamma_ambient: Vec<f64>,
}

impl RcNetwork {
    /// Builds a network from heat capacities (J/K), a symmetric conductance matrix between
    /// nodes (W/K, row-major, diagonal ignored) and conductances to ambient (W/K).
    ///
    /// Panics are impossible for valid physical input; invalid input (non-positive
    /// capacity, negative conductance, no path to ambient) returns `Err` with the reason.
    pub fn new(capacity: &[f64], between: &[f64], to_ambient: &[f64]) -> Result<Self, String> {
        let n = capacity.len();
        if between.len() != n * n || to_ambient.len() != n {
            return Err(format!(
                "network shape: {n} capacities, {} conductances, {} ambient links",
                between.len(),
                to_ambient.len()
            ));
        }
        if let Some(i) = capacity.iter().position(|c| !(c.is_finite() && *c > 0.0)) {
            return Err(format!(
                "node {i}: heat capacity must be finite and > 0, got {}",
                capacity[i]
            ));
        }
        if let Some(i) = between
            .iter()
            .chain(to_ambient)
            .position(|g| !(g.is_finite() && *g >= 0.0))
        {
            return Err(format!("conductance #{i} must be finite and ≥ 0"));
        }
        let mut laplacian = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                if i != j {
                    let g = 0.5 * (between[i * n + j] + between[j * n + i]);
                    laplacian[i * n + j] = -g;
                    laplacian[i * n + i] += g;
                }
            }
            laplacian[i * n + i] += to_ambient[i];
        }
        let sqrt_c: Vec<f64> = capacity.iter().map(|c| c.sqrt()).collect();
        let scaled: Vec<f64> = (0..n * n)
            .map(|k| laplacian[k] / (sqrt_c[k / n] * sqrt_c[k % n]))
            .collect();
        let (values, q) = symmetric_eigen(&scaled, n);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        let rates: Vec<f64> = order.iter().map(|&k| values[k]).collect();
        if rates[0] <= 0.0 {
            return Err("network has no path to ambient (a zero decay rate)".into());
        }
        let mut from_modes = vec![0.0; n * n];
        let mut to_modes = vec![0.0; n * n];
        for i in 0..n {
            for (m, &k) in order.iter().enumerate() {
                from_modes[i * n + m] = q[i * n + k] / sqrt_c[i];
                to_modes[m * n + i] = q[i * n + k] * sqrt_c[i];
            }
        }
        Ok(Self {
            n,
            capacity: capacity.to_vec(),
            to_ambient: to_ambient.to_vec(),
            laplacian,
            rates,
            from_modes,
            to_modes,
        })
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false: a network has at least one node to be valid.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Modal time constants `1/λₖ` (s), longest first.
    pub fn time_constants_s(&self) -> Vec<f64> {
        self.rates.iter().map(|r| 1.0 / r).collect()
    }

    /// Applies `S · diag(f(λ)) · S⁻¹` to a vector.
    fn modal_apply(&self, x: &[f64], f: impl Fn(f64) -> f64) -> Vec<f64> {
        let n = self.n;
        let modal: Vec<f64> = (0..n)
            .map(|m| {
                f(self.rates[m]) * (0..n).map(|i| self.to_modes[m * n + i] * x[i]).sum::<f64>()
            })
            .collect();
        (0..n)
            .map(|i| (0..n).map(|m| self.from_modes[i * n + m] * modal[m]).sum())
            .collect()
    }

    /// Steady-state temperatures (°C) for held power `P` (W) and ambient (°C).
    pub fn steady_state(&self, power_w: &[f64], ambient_c: f64) -> Vec<f64> {
        // T_ss = L⁻¹ (P + gₐ T_amb); L⁻¹ = S Λ⁻¹ S⁻¹ C⁻¹.
        let rhs: Vec<f64> = (0..self.n)
            .map(|i| (power_w[i] + self.to_ambient[i] * ambient_c) / self.capacity[i])
            .collect();
        self.modal_apply(&rhs, |l| 1.0 / l)
    }

    /// Exact state after `duration_s` with power and ambient held constant.
    pub fn advance(
        &self,
        temps_c: &[f64],
        power_w: &[f64],
        ambient_c: f64,
        duration_s: f64,
    ) -> Vec<f64> {
        let ss = self.steady_state(power_w, ambient_c);
        let dev: Vec<f64> = temps_c.iter().zip(&ss).map(|(t, s)| t - s).collect();
        let decayed = self.modal_apply(&dev, |l| (-l * duration_s).exp());
        decayed.iter().zip(&ss).map(|(d, s)| d + s).collect()
    }

    /// Time derivative `Ṫ` (K/s) at a state.
    pub fn derivative(&self, temps_c: &[f64], power_w: &[f64], ambient_c: f64) -> Vec<f64> {
        let n = self.n;
        (0..n)
            .map(|i| {
                let flow: f64 = (0..n)
                    .map(|j| -self.laplacian[i * n + j] * temps_c[j])
                    .sum();
                (flow + self.to_ambient[i] * ambient_c + power_w[i]) / self.capacity[i]
            })
            .collect()
    }

    /// Derivative of node `i` only (cheaper than [`Self::derivative`] in the sample loop).
    pub fn derivative_of(&self, i: usize, temps_c: &[f64], power_w: &[f64], ambient_c: f64) -> f64 {
        let n = self.n;
        let flow: f64 = (0..n)
            .map(|j| -self.laplacian[i * n + j] * temps_c[j])
            .sum();
        (flow + self.to_ambient[i] * ambient_c + power_w[i]) / self.capacity[i]
    }

    /// The exact zero-order-hold map for step `h_s`.
    pub fn discretise(&self, h_s: f64) -> Discrete {
        let n = self.n;
        let column = |e: &[f64], f: &dyn Fn(f64) -> f64| self.modal_apply(e, f);
        let mut phi = vec![0.0; n * n];
        let mut gamma_power = vec![0.0; n * n];
        let decay = |l: f64| (-l * h_s).exp();
        // ∫₀ʰ e^{-λs} ds = (1 − e^{-λh}) / λ, written with exp_m1 to keep precision for small λh.
        let integral = |l: f64| -(-l * h_s).exp_m1() / l;
        for j in 0..n {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            let phi_col = column(&e, &decay);
            e[j] = 1.0 / self.capacity[j];
            let gp_col = column(&e, &integral);
            for i in 0..n {
                phi[i * n + j] = phi_col[i];
                gamma_power[i * n + j] = gp_col[i];
            }
        }
        let amb_in: Vec<f64> = (0..n)
            .map(|i| self.to_ambient[i] / self.capacity[i])
            .collect();
        let gamma_ambient = column(&amb_in, &integral);
        Discrete {
            n,
            phi,
            gamma_power,
            gamma_ambient,
        }
    }
}

impl Discrete {
    /// The forcing term `Γ_P P + Γ_amb T_amb` for inputs held over the step, to pass to
    /// [`Self::step`].
    pub fn forcing(&self, power_w: &[f64], ambient_c: f64, out: &mut [f64]) {
        let rows = self.gamma_power.chunks_exact(self.n);
        for ((o, row), g_amb) in out.iter_mut().zip(rows).zip(&self.gamma_ambient) {
            let mut acc = g_amb * ambient_c;
            for (g, p) in row.iter().zip(power_w) {
                if *p != 0.0 {
                    acc += g * p;
                }
            }
            *o = acc;
        }
    }

    /// One exact step: `next = Φ · temps + forcing`.
    #[inline]
    pub fn step(&self, temps_c: &[f64], forcing: &[f64], next: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let row = &self.phi[i * n..(i + 1) * n];
            let mut acc = forcing[i];
            for (a, t) in row.iter().zip(temps_c) {
                acc += a * t;
            }
            next[i] = acc;
        }
    }
}
