//! The exact solver against closed-form solutions and an independent integrator.

use super::network::{asic, element, ThermalParams, BOARD, HOUSING, NODES};
use super::rc::RcNetwork;
use crate::hidden::HiddenEffects;
use crate::unit::{UnitModel, UnitParams};

#[test]
fn single_node_matches_newtons_law_of_cooling() {
    // C dT/dt = g (T_amb − T) + P  ⇒  T(t) = T_ss + (T0 − T_ss) e^{−t g / C}, T_ss = T_amb + P/g.
    let (c, g, p, amb, t0) = (50.0, 0.25, 0.8, 20.0, 35.0);
    let net = RcNetwork::new(&[c], &[0.0], &[g]).unwrap();
    let step = net.discretise(0.001);
    let mut x = [t0];
    let mut f = [0.0];
    step.forcing(&[p], amb, &mut f);
    let mut next = [0.0];
    for k in 1..=200_000 {
        step.step(&x, &f, &mut next);
        x = next;
        if k % 50_000 == 0 {
            let t = f64::from(k) * 0.001;
            let exact = amb + p / g + (t0 - amb - p / g) * (-t * g / c).exp();
            assert!((x[0] - exact).abs() < 1e-9, "t={t}: {} vs {exact}", x[0]);
        }
    }
    let jump = net.advance(&[t0], &[p], amb, 200.0);
    let exact = amb + p / g + (t0 - amb - p / g) * (-200.0 * g / c).exp();
    assert!((jump[0] - exact).abs() < 1e-10);
}

#[test]
fn two_nodes_match_the_closed_form_through_switching() {
    // Node 0 (C0) to ambient via g0, node 1 (C1) heated by P, linked by g1.
    // Eigenvalues of A = [[-(g0+g1)/C0, g1/C0], [g1/C1, -g1/C1]] in closed form.
    let (c0, c1, g0, g1, p, amb) = (40.0, 2.0, 0.3, 0.05, 0.5, 25.0);
    let net = RcNetwork::new(&[c0, c1], &[0.0, g1, g1, 0.0], &[g0, 0.0]).unwrap();
    let a = [[-(g0 + g1) / c0, g1 / c0], [g1 / c1, -g1 / c1]];
    let tr = a[0][0] + a[1][1];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let disc = (tr * tr / 4.0 - det).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
    // Deviation from the steady state evolves as Σ vₖ e^{λₖ t}, with eigenvectors (a01, λ − a00).
    let closed = |x0: [f64; 2], ss: [f64; 2], t: f64| -> [f64; 2] {
        let d = [x0[0] - ss[0], x0[1] - ss[1]];
        let v1 = [a[0][1], l1 - a[0][0]];
        let v2 = [a[0][1], l2 - a[0][0]];
        let det_v = v1[0] * v2[1] - v2[0] * v1[1];
        let k1 = (d[0] * v2[1] - v2[0] * d[1]) / det_v;
        let k2 = (v1[0] * d[1] - d[0] * v1[1]) / det_v;
        let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
        [
            ss[0] + k1 * v1[0] * e1 + k2 * v2[0] * e2,
            ss[1] + k1 * v1[1] * e1 + k2 * v2[1] * e2,
        ]
    };
    let ss_on = [amb + p / g0, amb + p / g0 + p / g1];
    let ss_off = [amb, amb];
    // 120 s on, 60 s off, 120 s on, stepping at 1 ms; compare at every switching instant.
    let step = net.discretise(0.001);
    let mut x = [amb, amb];
    let mut expected = [amb, amb];
    let mut next = [0.0; 2];
    let mut f = [0.0; 2];
    for (powered, seconds) in [(true, 120u32), (false, 60), (true, 120)] {
        step.forcing(&[0.0, if powered { p } else { 0.0 }], amb, &mut f);
        for _ in 0..seconds * 1000 {
            step.step(&x, &f, &mut next);
            x = next;
        }
        expected = closed(
            expected,
            if powered { ss_on } else { ss_off },
            f64::from(seconds),
        );
        // 300 000 exact steps accumulate rounding of ~1e-9 °C: five orders of magnitude below the
        // sensor's 0.005 °C step.
        for i in 0..2 {
            assert!(
                (x[i] - expected[i]).abs() < 1e-8,
                "node {i}: {} vs {}",
                x[i],
                expected[i]
            );
        }
    }
}

fn unit_network() -> (ThermalParams, RcNetwork) {
    let u = UnitParams::draw(3, 0, UnitModel::Physical, &HiddenEffects::default());
    let n = u.thermal.network().unwrap();
    (u.thermal, n)
}

#[test]
fn unit_network_matches_an_independent_rk4_through_on_off() {
    let (params, net) = unit_network();
    let p_on = params.power_w([1.0; 3], 1.0);
    let amb = 30.0;
    let step = net.discretise(0.001);
    let mut x = [amb; NODES];
    let mut y = x.to_vec(); // RK4 at 10 ms
    let mut next = [0.0; NODES];
    let mut f = [0.0; NODES];
    for (powered, seconds) in [(true, 120u32), (false, 60), (true, 120), (false, 300)] {
        let p = if powered { p_on } else { [0.0; NODES] };
        step.forcing(&p, amb, &mut f);
        for _ in 0..seconds * 1000 {
            step.step(&x, &f, &mut next);
            x = next;
        }
        let h = 0.01;
        for _ in 0..seconds * 100 {
            let k1 = net.derivative(&y, &p, amb);
            let y2: Vec<f64> = y.iter().zip(&k1).map(|(a, k)| a + 0.5 * h * k).collect();
            let k2 = net.derivative(&y2, &p, amb);
            let y3: Vec<f64> = y.iter().zip(&k2).map(|(a, k)| a + 0.5 * h * k).collect();
            let k3 = net.derivative(&y3, &p, amb);
            let y4: Vec<f64> = y.iter().zip(&k3).map(|(a, k)| a + h * k).collect();
            let k4 = net.derivative(&y4, &p, amb);
            for i in 0..NODES {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        for i in 0..NODES {
            assert!(
                (x[i] - y[i]).abs() < 1e-7,
                "node {i}: exact {} vs rk4 {}",
                x[i],
                y[i]
            );
        }
    }
}

#[test]
fn steady_state_balances_power() {
    let (params, net) = unit_network();
    let p = params.power_w([1.0; 3], 1.0);
    let ss = net.steady_state(&p, 30.0);
    // All heat leaves through the housing: g_ha (T_h − T_amb) = ΣP.
    let total: f64 = p.iter().sum();
    assert!((params.housing_to_ambient_w_per_k * (ss[HOUSING] - 30.0) - total).abs() < 1e-9);
    // Heat flows outward: ASIC hotter than board, board hotter than housing.
    for a in 0..3 {
        assert!(ss[asic(a)] > ss[BOARD] && ss[BOARD] > ss[HOUSING]);
        assert!(ss[element(a)] < ss[asic(a)]);
    }
    let rates = net.derivative(&ss, &p, 30.0);
    assert!(rates.iter().all(|r| r.abs() < 1e-12));
}

#[test]
fn slowest_mode_is_minutes_so_cool_down_is_done_within_the_hour() {
    // Over many drawn units: mostly cooled by 15 min (≥ 2.5 time constants, ≥ 92 %),
    // complete within 1 h (≥ 10 time constants), fastest mode seconds (the ASIC).
    for index in 0..50 {
        let u = UnitParams::draw(11, index, UnitModel::Physical, &HiddenEffects::default());
        let tau = u.thermal.network().unwrap().time_constants_s();
        let (slowest, fastest) = (tau[0], tau[tau.len() - 1]);
        assert!(
            (120.0..=360.0).contains(&slowest),
            "unit {index}: slowest {slowest} s"
        );
        assert!(
            (2.0..=20.0).contains(&fastest),
            "unit {index}: fastest {fastest} s"
        );
    }
}
