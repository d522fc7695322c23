//! Worlds: drawn deterministically per seed; a null world carries no undeclared effect; every
//! family, in every form, moves the recorded rate by a realistic amount; the truth stays out of
//! the recordings.

use drift_sim::world::effects::{EffectFamily, EffectForm, Source};
use drift_sim::world::{
    simulate_world_with, World, WorldCampaign, WorldRunOptions, WorldSpec, WorldTruth,
};
use drift_sim::{read_recording, Campaign, Field, Segment};

/// One field session at +30 °C, noise-free, 100 Hz: six 2-min activations, the orientation and
/// the supply changing before each.
fn field_campaign(world: &World) -> Campaign {
    let mut c = world.campaign(&WorldCampaign {
        sample_rate_hz: 100,
        noise_scale: 0.0,
        ..WorldCampaign::default()
    });
    c.set_points_celsius = vec![30.0];
    c.protocol = None;
    let f = c.field.clone().unwrap();
    c.field = Some(Field {
        sessions: 1,
        activations: 6,
        activation_s: [120.0, 120.0],
        orientation_change_probability: 1.0,
        ..f
    });
    c
}

fn segments(world: &World, c: &Campaign) -> Vec<Segment> {
    let dir = tempfile::tempdir().unwrap();
    let summary = world.simulate(c, dir.path(), |_| {}).unwrap();
    read_recording(&summary.files[0].recording)
        .unwrap()
        .segments
}

/// (largest drift max − min within an activation, spread of the activations' mean) of the
/// contribution `with − without`, over the axes.
fn contribution(with: &[Segment], without: &[Segment]) -> (f64, f64) {
    let (mut within, mut means) = (0.0f64, [Vec::new(), Vec::new(), Vec::new()]);
    for (s, n) in with.iter().zip(without) {
        for (a, axis_means) in means.iter_mut().enumerate() {
            let d: Vec<f64> = s.rate_dps[a]
                .iter()
                .zip(&n.rate_dps[a])
                .map(|(x, y)| f64::from(x - y))
                .collect();
            let (lo, hi) = d
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
            within = within.max(hi - lo);
            axis_means.push(d.iter().sum::<f64>() / d.len() as f64);
        }
    }
    let between = means
        .iter()
        .map(|m| {
            let (lo, hi) = m
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
            hi - lo
        })
        .fold(0.0, f64::max);
    (within, between)
}

/// Families whose channel is constant while powered: their offset-like forms shift the bias
/// between activations, not within one.
fn held(family: EffectFamily) -> bool {
    matches!(
        family,
        EffectFamily::Accelerometer | EffectFamily::SupplyVoltage | EffectFamily::AirPressure
    )
}

#[test]
fn every_family_in_every_form_moves_the_rate_by_a_realistic_amount() {
    let mut seed = 100;
    for family in EffectFamily::ALL {
        let forms: Vec<Option<EffectForm>> = if family.forms().is_empty() {
            vec![None]
        } else {
            family.forms().iter().map(|f| Some(*f)).collect()
        };
        for form in forms {
            seed += 1;
            let spec = WorldSpec {
                families: Some(vec![family]),
                forms: form.map(|f| vec![f]),
                ..WorldSpec::default()
            };
            let world = World::draw(seed, &spec);
            let truth = world.truth();
            assert_eq!(truth.families(), vec![family]);
            assert_eq!(truth.effects[0].form, form.or(truth.effects[0].form));
            let c = field_campaign(&world);
            let (within, between) =
                contribution(&segments(&world, &c), &segments(&world.null_twin(), &c));
            // Drift over an activation, or for a held channel the step between activations.
            let measured = if held(family) {
                within.max(between)
            } else {
                within
            };
            let label = format!(
                "{} {} (seed {seed}): within {within:.2e}, between {between:.2e} °/s",
                family.name(),
                form.map_or("-", EffectForm::name)
            );
            assert!((0.5e-3..=2e-2).contains(&measured), "{label}");
            // Not louder than the base drift between activations either.
            assert!(between <= 3e-2, "{label}");
        }
    }
}

#[test]
fn the_same_seed_draws_the_same_world() {
    for seed in 0..20 {
        let spec = WorldSpec::default();
        let a = World::draw(seed, &spec);
        assert_eq!(a, World::draw(seed, &spec));
        // The truth serialises and reads back (floats to within their last bit).
        let json = serde_json::to_string(a.truth()).unwrap();
        let back: WorldTruth = serde_json::from_str(&json).unwrap();
        assert_eq!(back.families(), a.truth().families());
        assert_eq!(back.effects.len(), a.truth().effects.len());
        assert_ne!(a.truth(), World::draw(seed + 1000, &spec).truth());
    }
    // Over many seeds every family turns up, and some worlds have none.
    let drawn: Vec<Vec<EffectFamily>> = (0..60)
        .map(|s| World::draw(s, &WorldSpec::default()).truth().families())
        .collect();
    for family in EffectFamily::ALL {
        assert!(
            drawn.iter().any(|f| f.contains(&family)),
            "{}",
            family.name()
        );
    }
    assert!(drawn.iter().any(Vec::is_empty));
}

#[test]
fn a_null_world_has_the_structure_and_no_undeclared_effect() {
    for seed in 0..20 {
        let null = World::draw(seed, &WorldSpec::null());
        let truth = null.truth();
        assert!(truth.effects.is_empty());
        for a in &truth.unit.axes {
            assert_eq!(a.thermal_lag_dps_per_c_per_s, 0.0);
        }
        assert_eq!(truth.unit.asic_power_per_c, 0.0);
        // The same structure and unit as any world of that seed.
        let full = World::draw(seed, &WorldSpec::with(&EffectFamily::ALL));
        assert_eq!(truth.structure, full.truth().structure);
        assert_eq!(truth.unit.thermal, full.truth().unit.thermal);
        assert_eq!(full.null_twin().truth().effects, Vec::new());
        assert_eq!(full.null_twin().truth().unit, truth.unit);
    }
    // Structures vary between seeds.
    let structures: Vec<_> = (0..10)
        .map(|s| World::draw(s, &WorldSpec::null()).truth().structure.clone())
        .collect();
    assert!(structures.iter().any(|s| s.gas_lag_s.is_some()));
    assert!(structures.iter().any(|s| s.gas_lag_s.is_none()));
    assert!(structures.iter().any(|s| s.temperature_lsb_raw > 1.0));
}

fn small_campaign() -> WorldCampaign {
    WorldCampaign {
        sample_rate_hz: 100,
        intervals_min: vec![2.0],
        repeats: 1,
        field_sessions: 1,
        field_activations: 3,
        ..WorldCampaign::default()
    }
}

#[test]
fn the_truth_stays_out_of_the_recordings() {
    let all = WorldSpec::with(&EffectFamily::ALL);
    let dir = tempfile::tempdir().unwrap();
    let null_dir = tempfile::tempdir().unwrap();
    let options = WorldRunOptions {
        campaign: small_campaign(),
        zero_drift_twin: true,
        ..WorldRunOptions::default()
    };
    let run = simulate_world_with(5, &all, dir.path(), &options).unwrap();
    let null = simulate_world_with(5, &WorldSpec::null(), null_dir.path(), &options).unwrap();
    // The truth file is where it says, and reads back as the world.
    let text = std::fs::read_to_string(&run.truth_path).unwrap();
    let world = World::draw(5, &all);
    assert_eq!(text, serde_json::to_string_pretty(world.truth()).unwrap());
    let truth: WorldTruth = serde_json::from_str(&text).unwrap();
    assert_eq!(truth.families(), EffectFamily::ALL.to_vec());
    assert!(run.truth_path.starts_with(dir.path().join("truth")));
    let words: Vec<&str> = EffectFamily::ALL
        .iter()
        .map(|f| f.name())
        .chain([
            "world.json",
            "effects",
            "coefficient",
            "gas_lag_s",
            "couplings",
        ])
        .filter(|w| !["humidity", "air_pressure", "supply_voltage"].contains(w))
        .collect();
    assert_eq!(run.summary.files.len(), null.summary.files.len());
    for (file, null_file) in run.summary.files.iter().zip(&null.summary.files) {
        let rec = read_recording(&file.recording).unwrap();
        let null_rec = read_recording(&null_file.recording).unwrap();
        // Same metadata keys and values (apart from nothing), same channels.
        assert_eq!(rec.metadata, null_rec.metadata);
        for (key, value) in &rec.metadata {
            for w in &words {
                assert!(!key.contains(w) && !value.contains(w), "{key} = {value}");
            }
        }
        let names = |r: &drift_sim::Recording| -> Vec<Vec<String>> {
            r.segments
                .iter()
                .map(|s| s.aux.keys().cloned().collect())
                .collect()
        };
        assert_eq!(names(&rec), names(&null_rec));
        for s in &rec.segments {
            for channel in [
                "accel_x",
                "supply_voltage",
                "chamber_set_point",
                "humidity",
                "air_pressure",
            ] {
                assert!(!s.aux[channel].values.is_empty(), "{channel}");
            }
        }
        // Nothing of the truth in the file's bytes either.
        let bytes = std::fs::read(&file.recording).unwrap();
        let haystack = String::from_utf8_lossy(&bytes);
        for w in &words {
            assert!(
                !haystack.contains(w),
                "`{w}` in {}",
                file.recording.display()
            );
        }
    }
    // The recordings folder holds recordings only.
    for entry in std::fs::read_dir(dir.path().join("recordings")).unwrap() {
        let path = entry.unwrap().path();
        assert_eq!(path.extension().unwrap(), "mcap", "{}", path.display());
    }
    // The zero-drift twin was recorded beside it, from the same schedule.
    let twin = run.zero_drift.unwrap();
    assert_eq!(twin.files.len(), run.summary.files.len());
    assert_eq!(twin.samples, run.summary.samples);
}

#[test]
fn a_chosen_truth_path_and_a_zero_drift_twin_without_drift() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("elsewhere").join("w.json");
    let options = WorldRunOptions {
        campaign: WorldCampaign {
            noise_scale: 0.0,
            ..small_campaign()
        },
        truth_path: Some(path.clone()),
        zero_drift_twin: true,
    };
    let out = dir.path().join("out");
    let run = simulate_world_with(9, &WorldSpec::with(&EffectFamily::ALL), &out, &options).unwrap();
    assert_eq!(run.truth_path, path);
    assert!(path.is_file());
    assert!(!out.join("truth").join("world.json").exists());
    let twin = run.zero_drift.unwrap();
    for file in &twin.files {
        // No systematic drift: the noise-free rate is the constant offset in every activation.
        let rec = read_recording(&file.recording).unwrap();
        for s in &rec.segments {
            for a in 0..3 {
                let v = &s.rate_dps[a];
                let (lo, hi) = v
                    .iter()
                    .fold((f32::MAX, f32::MIN), |(l, h), x| (l.min(*x), h.max(*x)));
                assert!(hi - lo < 1e-4, "{}: {lo} … {hi}", file.recording.display());
            }
        }
    }
    let world = World::draw(9, &WorldSpec::with(&EffectFamily::ALL));
    assert!(world.zero_drift_twin().truth().effects.is_empty());
    assert!(matches!(
        world
            .truth()
            .effects
            .iter()
            .find(|e| e.family == EffectFamily::CrossAxis)
            .unwrap()
            .terms[0]
            .source,
        Source::SensorTemperature { .. }
    ));
}

/// The oracle's regressor: the truth's effect series is exactly what the undeclared effect adds
/// to the rate (the world's rate less its null twin's, noise-free), for every family whose effect
/// is additive (self-heating changes the heating itself), and zero in a null world.
#[test]
fn the_truth_holds_the_undeclared_effect_alone() {
    let record = |world: &World, c: &Campaign| {
        let dir = tempfile::tempdir().unwrap();
        let summary = world.simulate(c, dir.path(), |_| {}).unwrap();
        let file = &summary.files[0];
        let truth = drift_sim::truth::read_truth(&file.truth).unwrap();
        (read_recording(&file.recording).unwrap().segments, truth)
    };
    let additive = EffectFamily::ALL
        .into_iter()
        .filter(|f| *f != EffectFamily::SelfHeating);
    for (k, family) in additive.enumerate() {
        let seed = 700 + k as u64;
        let world = World::draw(seed, &WorldSpec::with(&[family]));
        let c = field_campaign(&world);
        let (with, truth) = record(&world, &c);
        let (without, null_truth) = record(&world.null_twin(), &c);
        assert_eq!(truth.len(), with.len());
        let mut largest = 0.0f64;
        for ((s, n), t) in with.iter().zip(&without).zip(&truth) {
            for a in 0..3 {
                // 100 Hz: every sample is on the effect's grid.
                assert_eq!(
                    t.effect_dps[a].len(),
                    s.rate_dps[a].len(),
                    "{}",
                    family.name()
                );
                for (i, e) in t.effect_dps[a].iter().enumerate() {
                    let added = f64::from(s.rate_dps[a][i]) - f64::from(n.rate_dps[a][i]);
                    largest = largest.max(f64::from(*e).abs());
                    // Each rate is quantised to the output's LSB (2⁻¹⁴ °/s) and stored as f32
                    // beside the field's rotations.
                    let rounding =
                        4.0 * f64::from(f32::EPSILON) * f64::from(s.rate_dps[a][i].abs());
                    assert!(
                        (added - f64::from(*e)).abs() <= 1.0 / 16384.0 + 1e-7 + rounding,
                        "{} (seed {seed}) axis {a} sample {i}: rate adds {added:e}, truth says {e:e}",
                        family.name()
                    );
                }
            }
        }
        assert!(
            largest > 1e-4,
            "{}: the effect is {largest:e} °/s",
            family.name()
        );
        let zero = null_truth
            .iter()
            .flat_map(|t| t.effect_dps.iter().flatten());
        assert!(zero.into_iter().all(|e| *e == 0.0), "{}", family.name());
    }
}
