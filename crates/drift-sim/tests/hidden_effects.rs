//! Hidden effects: off by default, each one changes the truth when switched on, none of
//! them changes what a recording looks like structurally, and field sessions vary what
//! the protocol holds fixed.

mod common;

use drift_sim::truth::read_truth;
use drift_sim::{read_recording, simulate_campaign, Campaign, Field, HiddenEffects};

const EFFECTS: [&str; 6] = [
    "thermal_lag",
    "acceleration",
    "supply_voltage",
    "cross_axis",
    "rise_nonlinearity",
    "ageing",
];

/// Field session (orientation, voltage and ambient vary), noise-free, 4 activations of 20 s.
fn campaign(effects: HiddenEffects) -> Campaign {
    Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        noise_scale: 0.0,
        protocol: None,
        field: Some(Field {
            sessions: 1,
            activations: 4,
            activation_s: [20.0, 20.0],
            orientation_change_probability: 1.0,
            ..Field::default()
        }),
        effects,
        ..Campaign::default()
    }
}

/// (true bias per sample, recording topics+metadata keys, aux names) of the one file.
fn run(effects: HiddenEffects) -> (Vec<f32>, Vec<String>, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let summary = simulate_campaign(&campaign(effects), dir.path(), |_| {}).unwrap();
    let truth = read_truth(&summary.files[0].truth).unwrap();
    let bias: Vec<f32> = truth
        .iter()
        .flat_map(|t| t.systematic_bias_dps[0].iter().copied())
        .collect();
    let rec = read_recording(&summary.files[0].recording).unwrap();
    let keys: Vec<String> = rec.metadata.keys().cloned().collect();
    let aux: Vec<String> = rec.segments[0].aux.keys().cloned().collect();
    (bias, keys, aux)
}

#[test]
fn effects_are_off_by_default_and_each_changes_the_truth_alone() {
    assert!(Campaign::default().effects.active().is_empty());
    let (base, base_keys, base_aux) = run(HiddenEffects::default());
    for name in EFFECTS {
        let mut effects = HiddenEffects::default();
        effects.enable(name).unwrap();
        assert_eq!(effects.active(), vec![name]);
        let (bias, keys, aux) = run(effects);
        assert_eq!(bias.len(), base.len());
        let largest = bias
            .iter()
            .zip(&base)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        // Every effect moves the true bias by a visible but modest amount somewhere.
        assert!(largest > 1e-4, "{name}: largest change {largest:.2e} °/s");
        assert!(largest < 0.5, "{name}: largest change {largest:.2e} °/s");
        // The recording's shape (metadata keys, aux channels) does not reveal the effect.
        assert_eq!(keys, base_keys, "{name}");
        assert_eq!(aux, base_aux, "{name}");
    }
    assert!(HiddenEffects::default().enable("gremlins").is_err());
}

#[test]
fn field_sessions_vary_orientation_voltage_ambient_and_off_time() {
    let dir = tempfile::tempdir().unwrap();
    let mut c = campaign(HiddenEffects::default());
    c.noise_scale = 1.0;
    c.field.as_mut().unwrap().activations = 8;
    c.field.as_mut().unwrap().carry_probability = 0.5;
    let summary = simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let rec = read_recording(&summary.files[0].recording).unwrap();
    let first = |name: &str, k: usize| rec.segments[k].aux[name].values[0];
    let distinct = |name: &str| {
        let mut v: Vec<i64> = (0..rec.segments.len())
            .map(|k| (first(name, k) * 100.0).round() as i64)
            .collect();
        v.sort_unstable();
        v.dedup();
        v.len()
    };
    assert!(
        distinct("accel_x") > 1 || distinct("accel_y") > 1 || distinct("accel_z") > 1,
        "orientation never changed"
    );
    assert!(
        distinct("supply_voltage") > 1,
        "supply voltage never changed"
    );
    // Ambient ramps during activations (chamber set point channel follows the ambient).
    let ramped = rec.segments.iter().any(|s| {
        let v = &s.aux["chamber_set_point"].values;
        (v[v.len() - 1] - v[0]).abs() > 0.05
    });
    assert!(ramped, "no ambient ramp during any activation");
    let offs: Vec<f64> = rec
        .segments
        .iter()
        .skip(1)
        .filter_map(|s| s.labels.off_before_s)
        .collect();
    assert!(
        offs.windows(2).any(|w| (w[0] - w[1]).abs() > 1.0),
        "off-times do not vary: {offs:?}"
    );
    // |gravity| stays 1 g whatever the orientation.
    for s in &rec.segments {
        let g: f32 = ["accel_x", "accel_y", "accel_z"]
            .iter()
            .map(|n| s.aux[*n].values[0].powi(2))
            .sum();
        assert!((g.sqrt() - 1.0).abs() < 0.02, "|g| = {}", g.sqrt());
    }
}
