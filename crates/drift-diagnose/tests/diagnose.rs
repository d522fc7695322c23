//! The diagnosis on synthetic residuals: a planted effect is found and ranked first, at the level
//! where it acts; a candidate the paper's tables predict is marked absorbed; pure noise gives
//! nothing significant. (What the tables predict of a candidate is learnt from calibration data
//! by `drift_diagnose::absorb`; here it is planted: the tables are taken to predict all but a tiny part
//! of the time since switch-on, and nothing of the other candidates.)

use std::collections::BTreeMap;

use drift_diagnose::diagnose::{diagnose_axis, ActivationSeries};
use drift_recording::{SegmentLabels, SeriesKind, QUIET};

/// Deterministic noise in [−1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn activation(
    i: usize,
    effect: impl Fn(f64, f64, f64) -> f64,
    noise: &mut Lcg,
) -> ActivationSeries {
    let n = 300;
    let offset_input = noise.next(); // e.g. a supply deviation, constant per activation
    let mut residual = Vec::with_capacity(n);
    let (mut rate, mut supply, mut unrelated, mut time) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut wander = 0.0;
    for k in 0..n {
        let t = k as f64 * 0.1;
        let heating_rate =
            4.0 / 40.0 * (-t / 40.0).exp() * (1.0 + 0.3 * (t / 3.0 + i as f64).sin());
        wander += 0.05 * noise.next();
        let jitter = 0.002 * (0.5 * noise.next() + wander * 0.1);
        residual.push(effect(heating_rate, offset_input, t) + jitter + 0.001 * i as f64 % 0.003);
        rate.push(heating_rate);
        supply.push(5.0 + 0.4 * offset_input);
        unrelated.push(noise.next());
        time.push(t);
    }
    let absorbed_time: Vec<f64> = time.iter().map(|t| 1e-4 * (t * 7.0).sin()).collect();
    let candidates = BTreeMap::from([
        ("temperature rate".to_owned(), rate),
        ("aux:supply_voltage".to_owned(), supply),
        ("unrelated".to_owned(), unrelated),
        ("time since switch-on".to_owned(), time),
    ]);
    let mut left_over = candidates.clone();
    left_over.insert("time since switch-on".to_owned(), absorbed_time);
    ActivationSeries {
        labels: SegmentLabels {
            unit_id: "u".into(),
            set_point_celsius: 33.0,
            session_set_point_celsius: None,
            series_kind: SeriesKind::Field,
            series: 1,
            repeat: 1,
            activation: i as u32,
            interval_min: None,
            off_before_s: None,
        },
        residual_dps: [residual.clone(), residual.clone(), residual],
        candidates: [candidates.clone(), candidates.clone(), candidates],
        left_over: [left_over.clone(), left_over.clone(), left_over],
        baseline: Default::default(),
    }
}

fn run(
    effect: impl Fn(f64, f64, f64) -> f64 + Copy,
    seed: u64,
) -> drift_diagnose::diagnose::AxisDiagnosis {
    let mut noise = Lcg(seed);
    let activations: Vec<ActivationSeries> =
        (0..60).map(|i| activation(i, effect, &mut noise)).collect();
    diagnose_axis(&activations, 0, 5, 0.05, QUIET).expect("QUIET never stops")
}

#[test]
fn a_temperature_rate_effect_is_found_within_activations() {
    let d = run(|rate, _, _| 0.05 * rate, 1);
    let chosen = d.chosen().expect("a significant effect");
    assert_eq!(chosen.name, "temperature rate");
    assert_eq!(chosen.level, "within activations");
    assert!((chosen.coefficient - 0.05).abs() < 0.01, "{chosen:?}");
}

#[test]
fn a_supply_offset_is_found_between_activations() {
    let d = run(|_, offset, _| 0.004 * offset, 2);
    let chosen = d.chosen().expect("a significant effect");
    assert_eq!(chosen.name, "aux:supply_voltage");
    assert_eq!(chosen.level, "between activations");
    // 0.004 °/s per unit offset = 0.01 °/s per V (the supply swings 0.4 V per unit).
    assert!((chosen.coefficient - 0.01).abs() < 0.002, "{chosen:?}");
}

#[test]
fn model_inputs_are_absorbed_and_noise_is_not_significant() {
    let mut false_alarms = 0;
    for seed in 10..30 {
        let d = run(|_, _, _| 0.0, seed);
        let time = d
            .ranking
            .iter()
            .find(|c| c.name == "time since switch-on")
            .unwrap();
        assert_eq!(time.level, "absorbed by the model");
        assert!(!time.significant);
        false_alarms += usize::from(d.chosen().is_some());
    }
    // Family-wise α = 0.05 per axis: at most a few of 20 seeds may alarm by chance.
    assert!(
        false_alarms <= 2,
        "{false_alarms} of 20 null runs reported an effect"
    );
}

/// A ramped field series logs another set point at every switch-on; its activations still share
/// one fold, because a series is known by its recording's nominal set point.
#[test]
fn a_ramped_field_series_stays_in_one_fold() {
    let mut noise = Lcg(7);
    let activations: Vec<ActivationSeries> = (0..30)
        .map(|i| {
            let mut a = activation(i, |_, _, _| 0.0, &mut noise);
            a.labels.series = (i / 5) as u32;
            a.labels.session_set_point_celsius = Some(33.0);
            a.labels.set_point_celsius = 31.0 + 0.37 * i as f64;
            a
        })
        .collect();
    let (fold_of, folds) = drift_diagnose::diagnose::series_folds(&activations, 5);
    assert_eq!(folds, 5);
    for series in fold_of.chunks(5) {
        assert!(series.iter().all(|&f| f == series[0]), "{fold_of:?}");
    }
}

/// The baseline is fitted before any candidate: a residual that follows the bench's ambient (a
/// baseline column) is not a discovery, even for a candidate that follows the ambient too, and a
/// real effect beside it is still found.
#[test]
fn what_the_baseline_explains_is_no_discovery() {
    let mut noise = Lcg(11);
    let activations: Vec<ActivationSeries> = (0..60)
        .map(|i| {
            let mut a = activation(i, |_, _, _| 0.0, &mut noise);
            a.labels.series = (i / 3) as u32;
            let ramp: Vec<f64> = (0..300)
                .map(|k| (k as f64 / 300.0) * (1.0 + (i % 4) as f64) + 0.1 * noise.next())
                .collect();
            // The unit's residual follows the ambient ramp; a channel that follows the ambient
            // too (a housing thermistor) is offered as a candidate.
            for (y, r) in a.residual_dps[0].iter_mut().zip(&ramp) {
                *y += 0.01 * r;
            }
            let follower: Vec<f64> = ramp.iter().map(|r| r + 0.05 * noise.next()).collect();
            a.candidates[0].insert("aux:housing".into(), follower.clone());
            a.left_over[0].insert("aux:housing".into(), follower);
            a.baseline[0].insert("ambient".into(), ramp);
            a
        })
        .collect();
    let d = diagnose_axis(&activations, 0, 5, 0.05, QUIET).expect("QUIET never stops");
    assert_eq!(d.baseline, ["ambient"]);
    assert!(d.baseline_explained_within > 0.5, "{d:?}");
    assert!(d.chosen().is_none(), "{:?}", d.chosen());
    let housing = d.ranking.iter().find(|c| c.name == "aux:housing").unwrap();
    assert!(housing.explained < 0.05, "{housing:?}");
    // Without the baseline the follower would have been the discovery.
    let without: Vec<ActivationSeries> = activations
        .iter()
        .cloned()
        .map(|mut a| {
            a.baseline = Default::default();
            a
        })
        .collect();
    let d = diagnose_axis(&without, 0, 5, 0.05, QUIET).expect("QUIET never stops");
    assert_eq!(d.chosen().map(|c| c.name.as_str()), Some("aux:housing"));
}

/// The activations of [`run`] with the rate candidate named as the diagnosis names the sensor's
/// own temperature rate: a term of the unit's thermal response.
fn with_sensor_rate(
    effect: impl Fn(f64, f64, f64) -> f64 + Copy,
    seed: u64,
) -> Vec<ActivationSeries> {
    let mut noise = Lcg(seed);
    (0..60)
        .map(|i| {
            let mut a = activation(i, effect, &mut noise);
            for maps in [&mut a.candidates, &mut a.left_over] {
                for map in maps.iter_mut() {
                    if let Some(v) = map.remove("temperature rate") {
                        map.insert("temperature rate X (τ 8 s)".to_owned(), v);
                    }
                }
            }
            a
        })
        .collect()
}

#[test]
fn the_thermal_response_is_the_own_axis_rise_squared_and_rates() {
    use drift_diagnose::candidates::Kind;
    for name in [
        "rise² X",
        "temperature rate Y (τ 2 s)",
        "element rate Z (τ 120 s)",
    ] {
        assert!(Kind::is_thermal_response(name), "{name}");
    }
    // A neighbour's heating, a channel, the time: effects.
    for name in [
        "element rate Y on X (τ 30 s)",
        "rise Y",
        "aux:supply_voltage × rise X",
        "time since switch-on",
        "temperature rate",
    ] {
        assert!(!Kind::is_thermal_response(name), "{name}");
    }
}

#[test]
fn the_thermal_response_is_selected_before_effects_and_is_not_one() {
    // The unit's own rate response and a supply offset: the response first, flagged as such,
    // then the supply as the effect over it.
    let d = diagnose_axis(
        &with_sensor_rate(|rate, offset, _| 0.05 * rate + 0.004 * offset, 3),
        0,
        5,
        0.05,
        QUIET,
    )
    .expect("QUIET never stops");
    let names: Vec<(&str, bool)> = d
        .selected
        .iter()
        .map(|s| (s.name.as_str(), s.thermal_response))
        .collect();
    assert_eq!(
        names,
        [
            ("temperature rate X (τ 8 s)", true),
            ("aux:supply_voltage", false)
        ],
        "{d:#?}"
    );
    let supply = d
        .ranking
        .iter()
        .find(|c| c.name == "aux:supply_voltage")
        .unwrap();
    assert!(supply.significant && !supply.thermal_response);
    assert!(d.size_threshold > 0.0 && d.response_size_threshold > 0.0);

    // The response alone: selected, and no effect beyond it.
    let d = diagnose_axis(
        &with_sensor_rate(|rate, _, _| 0.05 * rate, 4),
        0,
        5,
        0.05,
        QUIET,
    )
    .expect("QUIET never stops");
    assert_eq!(d.selected.len(), 1, "{:#?}", d.selected);
    assert!(d.selected[0].thermal_response);
    assert!(d
        .ranking
        .iter()
        .all(|c| !c.significant || c.thermal_response));
}
