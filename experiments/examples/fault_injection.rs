//! The error temperature-sensor faults leave, beside the fault-free case:
//! `cargo run --release -p experiments --example fault_injection` (about a minute; docs/reliability.md).
//!
//! One small campaign is simulated fault-free and once per fault kind with the same seed: faults
//! come from a random stream of their own, so each faulty twin differs from the clean one only at
//! its faults. Tables fitted on the clean calibration set points (+30/+40 °C) correct the +33 °C
//! validation activations of every twin; the table gives the paper's drift metric (max − min of
//! the 1-s mean of the corrected rate, °/s; mean over activations × axes) and how often the
//! corrector flagged the fault. The last column says what the fitter does when the calibration
//! recordings themselves carry the fault (and, when it fits, what those tables leave on the clean
//! validation data).

use drift_core::Flags;
use drift_evaluate::evaluate::{evaluate, ModelKind};
use drift_evaluate::pipeline::{self, Options};
use drift_fit::{FitSettings, FittedUnit};
use drift_recording::read_recording;
use drift_sim::faults::{FaultWindow, SensorFaults, Spikes};
use drift_sim::{simulate_campaign, Campaign, Protocol};

fn campaign(faults: SensorFaults) -> Campaign {
    Campaign {
        name: "faults".into(),
        seed: 11,
        units: 1,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 15.0, 30.0],
            repeats: 2,
            ..Protocol::default()
        }),
        faults,
        ..Campaign::default()
    }
}

fn options() -> Options {
    Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: vec![33.0],
        fit: FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    }
}

/// Mean drift (modified, standard) over the validation activations × axes, and the share of
/// activation-axes whose flags include `flag`.
fn validation(
    dir: &std::path::Path,
    fitted: &FittedUnit,
    flag: Flags,
) -> anyhow::Result<(f64, f64, f64)> {
    let files = pipeline::recording_files(dir)?;
    let file = files
        .iter()
        .find(|f| f.to_string_lossy().contains("sp+33.0C"))
        .ok_or_else(|| anyhow::anyhow!("no +33 °C recording in {}", dir.display()))?;
    let recording = read_recording(file)?;
    let settings = FitSettings::default();
    let (mut modified, mut standard, mut flagged, mut n) = (0.0, 0.0, 0usize, 0usize);
    for segment in &recording.segments {
        let result = evaluate(fitted, segment, &settings);
        for m in &result.models {
            for axis in 0..3 {
                match m.model {
                    ModelKind::Modified => {
                        modified += m.drift_dps[axis];
                        flagged += usize::from(Flags(m.flags[axis]).intersects(flag));
                        n += 1;
                    }
                    ModelKind::Standard => standard += m.drift_dps[axis],
                    _ => {}
                }
            }
        }
    }
    let n = n.max(1) as f64;
    Ok((modified / n, standard / n, flagged as f64 / n))
}

fn main() -> anyhow::Result<()> {
    let root = tempfile::tempdir()?;
    let window = FaultWindow::default();
    let kinds: [(&str, SensorFaults, Flags); 4] = [
        ("none", SensorFaults::default(), Flags::FAULTS),
        (
            "dropout (3–10 s, one axis)",
            SensorFaults {
                dropout: Some(window.clone()),
                ..SensorFaults::default()
            },
            Flags::TEMPERATURE_INVALID,
        ),
        (
            "stuck reading (3–10 s, one axis)",
            SensorFaults {
                stuck: Some(window),
                ..SensorFaults::default()
            },
            Flags::TEMPERATURE_STUCK,
        ),
        (
            "10 spikes of ±5 °C",
            SensorFaults {
                spikes: Some(Spikes::default()),
                ..SensorFaults::default()
            },
            Flags::FAULTS,
        ),
    ];
    let mut fitted = None;
    println!("| fault (every validation activation) | modified °/s | Δ vs none | standard (absolute) °/s | activation-axes flagged | fit on faulty calibration data |");
    println!("|---|---:|---:|---:|---:|---|");
    let mut clean = 0.0;
    for (name, faults, flag) in kinds {
        let dir = root.path().join(name.split(' ').next().unwrap_or("x"));
        simulate_campaign(&campaign(faults), &dir, |_| {})?;
        let files = pipeline::recording_files(&dir)?;
        let fit = pipeline::run(&files, &options(), false, drift_recording::QUIET);
        let clean_dir = root.path().join("none");
        let fit_note = match &fit {
            // What fitting on the faulty twin costs: its tables on the clean validation data.
            Ok(outcome) if name != "none" => {
                let (m, _, _) = validation(&clean_dir, &outcome.fitted[0], Flags::FAULTS)?;
                format!("fits; those tables leave {m:.4} on clean data")
            }
            Ok(_) => "fits".to_owned(),
            Err(e) => format!(
                "refused: {}",
                e.to_string().split(": ").last().unwrap_or_default()
            ),
        };
        let model: &FittedUnit = match &fitted {
            Some(f) => f,
            None => {
                let outcome = fit?;
                fitted.insert(
                    outcome
                        .fitted
                        .into_iter()
                        .next()
                        .ok_or_else(|| anyhow::anyhow!("no unit fitted"))?,
                )
            }
        };
        let (modified, standard, share) = validation(&dir, model, flag)?;
        if name == "none" {
            clean = modified;
        }
        println!(
            "| {name} | {modified:.4} | {:+.4} | {standard:.4} | {:.0} % | {fit_note} |",
            modified - clean,
            share * 100.0
        );
    }
    Ok(())
}
