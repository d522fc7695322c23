//! A recording says its own temperature-sensor scale (`temperature_raw_per_celsius`,
//! `temperature_raw_at_zero_celsius`): the campaign re-recorded at 100 raw/°C with 500 raw at 0 °C
//! fits tables stamped with that scale, whose corrections leave the drift the 200 raw/°C original
//! leaves; evaluation data at another scale than the tables is refused.

use std::path::Path;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::pipeline::{self, Options, Outcome, PipelineError};
use drift_evaluate::summary::summarise;
use drift_fit::FitSettings;
use drift_recording::{
    read_campaign_dir, read_recording, write_recording, Recording, TemperatureScale,
    RECORDINGS_DIR, TEMPERATURE_MISSING_RAW,
};
use drift_sim::{simulate_campaign, Campaign, Protocol};

const OTHER: TemperatureScale = TemperatureScale {
    raw_per_celsius: 100.0,
    raw_at_zero_celsius: 500.0,
};

fn campaign() -> Campaign {
    Campaign {
        name: "scale".into(),
        seed: 23,
        units: 1,
        noise_scale: 1.0,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 30.0],
            repeats: 2,
            activations: 3,
            activation_s: 60.0,
            ..Protocol::default()
        }),
        ..Campaign::default()
    }
}

/// `recording` with its raw temperatures re-expressed at `scale` (same °C, rounded to its units).
fn rescaled(recording: &Recording, scale: TemperatureScale) -> Recording {
    let mut out = recording.clone();
    for segment in &mut out.segments {
        let from = segment.temperature_scale;
        for axis in &mut segment.temperature_raw {
            for raw in axis.iter_mut() {
                assert_ne!(*raw, TEMPERATURE_MISSING_RAW);
                *raw = scale.raw(from.celsius(f64::from(*raw))).round() as i16;
            }
        }
        segment.temperature_scale = scale;
    }
    out
}

fn write_campaign(recordings: &[Recording], dir: &Path) {
    let folder = dir.join(RECORDINGS_DIR);
    std::fs::create_dir_all(&folder).unwrap();
    for recording in recordings {
        let name = recording.path.file_name().unwrap();
        write_recording(recording, &folder.join(name)).unwrap();
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

fn run(dir: &Path) -> Result<Outcome, PipelineError> {
    let files = pipeline::recording_files(dir).unwrap();
    pipeline::run(&files, &options(), false, drift_recording::QUIET)
}

fn mean_drift(outcome: &Outcome, model: ModelKind) -> f64 {
    let values: Vec<f64> = summarise(&outcome.results)
        .iter()
        .filter(|r| r.model == model.name())
        .map(|r| r.drift_dps)
        .collect();
    values.iter().sum::<f64>() / values.len() as f64
}

#[test]
fn a_recording_at_another_scale_fits_and_corrects_right() {
    let original = tempfile::tempdir().unwrap();
    simulate_campaign(&campaign(), original.path(), |_| {}).unwrap();
    let recordings = read_campaign_dir(original.path()).unwrap();
    let other = tempfile::tempdir().unwrap();
    let at_other: Vec<Recording> = recordings.iter().map(|r| rescaled(r, OTHER)).collect();
    write_campaign(&at_other, other.path());
    // The file says its scale, and the reader hands it to every activation.
    let name = at_other[0].path.file_name().unwrap();
    let back = read_recording(&other.path().join(RECORDINGS_DIR).join(name)).unwrap();
    assert_eq!(back.metadata["temperature_raw_per_celsius"], "100");
    assert_eq!(back.metadata["temperature_raw_at_zero_celsius"], "500");
    assert!(back.segments.iter().all(|s| s.temperature_scale == OTHER));

    let (a, b) = (run(original.path()).unwrap(), run(other.path()).unwrap());
    let (fa, fb) = (&a.fitted[0], &b.fitted[0]);
    for settings in [
        fb.modified.settings,
        fb.by_history.settings,
        fb.standard.settings,
        fb.third_order.settings,
        fb.relative.settings,
    ] {
        assert_eq!(settings.raw_per_celsius, 100.0);
        assert_eq!(settings.raw_at_zero_celsius, 500.0);
    }
    assert_eq!(fa.modified.settings.raw_per_celsius, 200.0);
    // The same temperatures in °C: the calibrated ambients agree to the coarser scale's step.
    for axis in 0..3 {
        let (x, y) = (
            fa.modified.axes[axis].ambients[0].ambient_celsius,
            fb.modified.axes[axis].ambients[0].ambient_celsius,
        );
        assert!((x - y).abs() < 0.02, "axis {axis}: {x} °C vs {y} °C");
    }
    for model in ModelKind::ALL {
        let (x, y) = (mean_drift(&a, model), mean_drift(&b, model));
        assert!(
            (x - y).abs() <= 0.1 * x,
            "{model:?}: {x:.5} °/s at 200 raw/°C, {y:.5} °/s at 100 raw/°C + 500"
        );
    }
}

#[test]
fn evaluation_data_at_another_scale_than_the_tables_is_refused() {
    let original = tempfile::tempdir().unwrap();
    simulate_campaign(&campaign(), original.path(), |_| {}).unwrap();
    let recordings = read_campaign_dir(original.path()).unwrap();
    // The validation recording alone is re-expressed at another scale.
    let mixed: Vec<Recording> = recordings
        .iter()
        .map(|r| {
            if r.segments[0].labels.nominal_set_point_celsius() == 33.0 {
                rescaled(r, OTHER)
            } else {
                r.clone()
            }
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    write_campaign(&mixed, dir.path());
    let error = run(dir.path()).unwrap_err().to_string();
    assert!(
        error.contains("temperature scale 100 raw/°C, 500 raw at 0 °C")
            && error.contains("fitted on recordings at 200 raw/°C, 0 raw at 0 °C"),
        "{error}"
    );
}
