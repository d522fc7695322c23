//! End to end on small simulated campaigns: simulate → fit → correct → the floors; the fit
//! never depends on validation recordings; field sessions whose ambient ramps are evaluated under
//! their nominal set point; bad campaigns give clear errors.

use std::path::Path;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::pipeline::{self, Options, Outcome};
use drift_evaluate::summary::{summarise, Split};
use drift_fit::FitSettings;
use drift_sim::{simulate_campaign, Campaign, Field, Protocol, UnitModel};

fn small(seed: u64, noise_scale: f64) -> Campaign {
    Campaign {
        name: "small".into(),
        seed,
        units: 1,
        noise_scale,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 30.0],
            repeats: 2,
            ..Protocol::default()
        }),
        ..Campaign::default()
    }
}

fn options() -> Options {
    Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: vec![33.0],
        fit: FitSettings::default(),
        held_out_repeats: true,
        evaluate: true,
        switch_on_ambient: None,
    }
}

fn run(dir: &Path) -> Outcome {
    let files = pipeline::recording_files(dir).unwrap();
    pipeline::run(&files, &options(), false, drift_recording::QUIET).unwrap()
}

/// Mean drift over axes of `model` at `set_point` in `split`.
fn drift(outcome: &Outcome, split: Split, set_point: f64, model: ModelKind) -> f64 {
    let records = summarise(&outcome.results);
    let values: Vec<f64> = records
        .iter()
        .filter(|r| {
            r.split == split
                && (r.set_point_celsius - set_point).abs() < 1e-6
                && r.model == model.name()
        })
        .map(|r| r.drift_dps)
        .collect();
    assert_eq!(values.len(), 3, "{split:?} {set_point} {model:?}");
    values.iter().sum::<f64>() / 3.0
}

#[test]
fn modified_beats_standard_at_every_set_point() {
    let dir = tempfile::tempdir().unwrap();
    simulate_campaign(&small(7, 1.0), dir.path(), |_| {}).unwrap();
    let outcome = run(dir.path());
    for (split, set_point) in [
        (Split::HeldOutRepeat, 30.0),
        (Split::Validation, 33.0),
        (Split::HeldOutRepeat, 40.0),
    ] {
        let standard = drift(&outcome, split, set_point, ModelKind::Standard);
        let modified = drift(&outcome, split, set_point, ModelKind::Modified);
        let uncorrected = drift(&outcome, split, set_point, ModelKind::Uncorrected);
        assert!(
            standard >= 1.3 * modified,
            "{set_point} °C: standard {standard:.4} vs modified {modified:.4}"
        );
        assert!(
            modified < uncorrected,
            "{set_point} °C: modified {modified:.4} vs uncorrected {uncorrected:.4}"
        );
    }
}

#[test]
fn without_noise_the_fit_removes_over_90_percent_of_the_drift() {
    let dir = tempfile::tempdir().unwrap();
    simulate_campaign(&small(8, 0.0), dir.path(), |_| {}).unwrap();
    let outcome = run(dir.path());
    for (split, set_point) in [
        (Split::HeldOutRepeat, 30.0),
        (Split::Validation, 33.0),
        (Split::HeldOutRepeat, 40.0),
    ] {
        let modified = drift(&outcome, split, set_point, ModelKind::Modified);
        let uncorrected = drift(&outcome, split, set_point, ModelKind::Uncorrected);
        assert!(
            modified < 0.1 * uncorrected,
            "{set_point} °C: modified {modified:.5} vs uncorrected {uncorrected:.5}"
        );
    }
}

#[test]
fn the_fit_never_depends_on_validation_recordings() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    simulate_campaign(&small(9, 1.0), a.path(), |_| {}).unwrap();
    simulate_campaign(&small(9, 1.0), b.path(), |_| {}).unwrap();
    // Campaign b's +33 °C recordings come from another seed and are then corrupted outright.
    let other = tempfile::tempdir().unwrap();
    simulate_campaign(
        &Campaign {
            set_points_celsius: vec![33.0],
            ..small(99, 1.0)
        },
        other.path(),
        |_| {},
    )
    .unwrap();
    for file in pipeline::recording_files(other.path()).unwrap() {
        let name = file.file_name().unwrap().to_owned();
        let target = b.path().join("recordings").join(&name);
        let mut bytes = std::fs::read(&file).unwrap();
        std::fs::write(&target, &bytes).unwrap();
        // Flip bytes in the middle of the data: decoding this file would fail.
        let middle = bytes.len() / 2;
        bytes[middle..middle + 64]
            .iter_mut()
            .for_each(|b| *b ^= 0xA5);
        std::fs::write(&target, &bytes).unwrap();
    }
    let fit = |dir: &Path| {
        let files = pipeline::recording_files(dir).unwrap();
        let options = Options {
            validation_set_points: Vec::new(),
            held_out_repeats: false,
            evaluate: false,
            ..options()
        };
        pipeline::run(&files, &options, false, drift_recording::QUIET)
            .unwrap()
            .fitted
    };
    let (fa, fb) = (fit(a.path()), fit(b.path()));
    assert_eq!(fa.len(), 1);
    assert_eq!(fa[0].modified, fb[0].modified);
    assert_eq!(fa[0].standard, fb[0].standard);
    assert_eq!(fa[0].third_order, fb[0].third_order);
}

#[test]
fn a_campaign_without_first_activations_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    // One activation per series only, at one set point: no curves after a warm start, but also
    // nothing wrong; then a protocol whose intervals are all short has no independent curve.
    let campaign = Campaign {
        set_points_celsius: vec![30.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0],
            repeats: 1,
            activations: 1,
            activation_s: 30.0,
            ..Protocol::default()
        }),
        ..small(10, 1.0)
    };
    simulate_campaign(&campaign, dir.path(), |_| {}).unwrap();
    let files = pipeline::recording_files(dir.path()).unwrap();
    let options = Options {
        calibration_set_points: vec![30.0],
        validation_set_points: vec![],
        ..options()
    };
    let outcome = pipeline::run(&files, &options, false, drift_recording::QUIET).unwrap();
    // A single independent curve still gives a valid (degenerate: no heating dynamics) table.
    assert_eq!(outcome.fitted[0].curve_keys.len(), 1);

    // Calibration set points that the campaign does not have: a clear error.
    let options = Options {
        calibration_set_points: vec![50.0],
        ..options
    };
    let error = pipeline::run(&files, &options, false, drift_recording::QUIET).unwrap_err();
    assert!(
        format!("{error:#}").contains("no protocol activations at the calibration set points"),
        "{error:#}"
    );
}

/// A short protocol (enough for a fit) and one field session per set point whose ambient ramps
/// and is carried: its activations switch on at ambients other than the set point.
fn ramped(seed: u64, unit_model: UnitModel) -> Campaign {
    Campaign {
        name: "ramped".into(),
        seed,
        units: 1,
        unit_model,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0],
            activations: 3,
            repeats: 1,
            rest_min: 30.0,
            ..Protocol::default()
        }),
        field: Some(Field {
            sessions: 1,
            activations: 5,
            activation_s: [20.0, 40.0],
            off_min: [0.5, 5.0],
            ambient_ramp_c_per_min: 6.0,
            carry_probability: 0.5,
            rest_min: 10.0,
            ..Field::default()
        }),
        ..Campaign::default()
    }
}

/// Activations per set point of `split`'s records (one unit; the same count on every model and
/// axis).
fn activations_per_set_point(outcome: &Outcome, split: Split) -> Vec<(f64, usize)> {
    let records = summarise(&outcome.results);
    let mut rows: Vec<(f64, usize)> = records
        .iter()
        .filter(|r| r.split == split && r.model == "uncorrected" && r.axis == "X")
        .map(|r| (r.set_point_celsius, r.activations))
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    rows
}

#[test]
fn ramped_field_sessions_are_evaluated_under_their_nominal_set_point() {
    let dir = tempfile::tempdir().unwrap();
    simulate_campaign(&ramped(11, UnitModel::Physical), dir.path(), |_| {}).unwrap();
    let outcome = run(dir.path());
    // The sessions did ramp: most field activations switch on away from their set point.
    let field: Vec<_> = outcome
        .results
        .iter()
        .filter(|(split, _)| *split == Split::Field)
        .map(|(_, r)| &r.labels)
        .collect();
    assert_eq!(field.len(), 15);
    let away = field
        .iter()
        .filter(|l| (l.set_point_celsius - l.nominal_set_point_celsius()).abs() > 1e-6)
        .count();
    assert!(away >= 10, "{field:#?}");
    // One field row per session set point, each with the session's 5 activations.
    assert_eq!(
        activations_per_set_point(&outcome, Split::Field),
        [(30.0, 5), (33.0, 5), (40.0, 5)]
    );
    // Validation: the +33 °C protocol (2 intervals × 3 activations); field activations stay field.
    assert_eq!(
        activations_per_set_point(&outcome, Split::Validation),
        [(33.0, 6)]
    );
}

#[test]
fn the_noise_floor_keeps_every_activation_of_the_twins_validation_sessions() {
    let dir = tempfile::tempdir().unwrap();
    simulate_campaign(
        &ramped(12, UnitModel::ZeroSystematicDrift),
        dir.path(),
        |_| {},
    )
    .unwrap();
    let files = pipeline::recording_files(dir.path()).unwrap();
    let outcome = pipeline::run(&files, &options(), true, drift_recording::QUIET).unwrap();
    assert!(outcome.results.iter().all(|(s, _)| *s == Split::NoiseFloor));
    // The +33 °C protocol's 6 activations and the +33 °C field session's 5, wherever the ramp
    // had taken the ambient at switch-on.
    assert_eq!(
        activations_per_set_point(&outcome, Split::NoiseFloor),
        [(33.0, 11)]
    );
}
