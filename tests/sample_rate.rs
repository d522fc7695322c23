//! The drift metric and the fit measure durations, not sample counts: one simulated campaign,
//! block-averaged from 1000 Hz to 250, 200, 100 and 50 Hz, reports every model's drift within 10 %
//! at every rate (the 1-s low-pass stays 1 s, the fit's windows and reference times stay where
//! they were, also where the analysis grid is not a whole number of samples).

use std::path::Path;

use drift_evaluate::evaluate::ModelKind;
use drift_evaluate::pipeline::{self, Options};
use drift_evaluate::summary::summarise;
use drift_fit::FitSettings;
use drift_recording::{block_means, read_campaign_dir, write_recording, Recording, RECORDINGS_DIR};
use drift_sim::{simulate_campaign, Campaign, Protocol};

fn campaign() -> Campaign {
    Campaign {
        name: "rates".into(),
        seed: 21,
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

/// Writes `recordings` block-averaged by `factor` as a campaign folder under `dir`.
fn write_at(recordings: &[Recording], factor: usize, dir: &Path) {
    let folder = dir.join(RECORDINGS_DIR);
    std::fs::create_dir_all(&folder).unwrap();
    for recording in recordings {
        let rate = recording.sample_rate_hz / factor as u32;
        let mut metadata = recording.metadata.clone();
        metadata.insert("sample_rate_hz".into(), rate.to_string());
        let lower = Recording {
            metadata,
            sample_rate_hz: rate,
            segments: recording
                .segments
                .iter()
                .map(|s| {
                    let mut lower = block_means(s, rate).unwrap();
                    // The format records auxiliary channels at 100 Hz: a slower recording has none.
                    if rate < 100 {
                        lower.aux.clear();
                    }
                    lower
                })
                .collect(),
            ..recording.clone()
        };
        let name = recording.path.file_name().unwrap();
        write_recording(&lower, &folder.join(name)).unwrap();
    }
}

/// Mean drift of every model over every record (set point, split, axis) of the campaign in `dir`,
/// whose recordings are at `rate` Hz: every fitted model states that rate for firmware.
fn drifts(dir: &Path, rate: u32) -> Vec<(ModelKind, f64)> {
    let files = pipeline::recording_files(dir).unwrap();
    let options = Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: vec![33.0],
        fit: FitSettings::default(),
        held_out_repeats: true,
        evaluate: true,
        switch_on_ambient: None,
    };
    let outcome = pipeline::run(&files, &options, false, drift_recording::QUIET).unwrap();
    for unit in &outcome.fitted {
        let stated = [
            unit.modified.settings,
            unit.by_history.settings,
            unit.standard.settings,
            unit.third_order.settings,
            unit.relative.settings,
            unit.relative_cubic.settings,
        ]
        .map(|s| s.sample_rate_hz);
        assert_eq!(stated, [rate as f32; 6], "{}", unit.unit_id);
    }
    let records = summarise(&outcome.results);
    ModelKind::ALL
        .iter()
        .map(|&model| {
            let values: Vec<f64> = records
                .iter()
                .filter(|r| r.model == model.name())
                .map(|r| r.drift_dps)
                .collect();
            assert!(!values.is_empty(), "{model:?}");
            (model, values.iter().sum::<f64>() / values.len() as f64)
        })
        .collect()
}

#[test]
fn every_models_drift_is_the_same_at_1000_250_200_100_and_50_hz() {
    let full = tempfile::tempdir().unwrap();
    simulate_campaign(&campaign(), full.path(), |_| {}).unwrap();
    let recordings = read_campaign_dir(full.path()).unwrap();
    assert!(recordings.iter().all(|r| r.sample_rate_hz == 1000));
    let at_1000 = drifts(full.path(), 1000);
    // 250 and 50 Hz: the 10-ms analysis grid is not whole samples there (`FitSettings::grid_at`).
    for factor in [4, 5, 10, 20] {
        let lower = tempfile::tempdir().unwrap();
        write_at(&recordings, factor, lower.path());
        let rate = 1000 / factor as u32;
        let at_lower = drifts(lower.path(), rate);
        for ((model, fast), (_, slow)) in at_1000.iter().zip(&at_lower) {
            assert!(
                (slow - fast).abs() <= 0.1 * fast,
                "{model:?}: {fast:.5} °/s at 1000 Hz, {slow:.5} °/s at {rate} Hz"
            );
        }
    }
}
