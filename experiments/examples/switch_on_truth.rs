//! How far the rate filter's predicted start is from the simulator's truth (its table is in
//! experiments/README.md). Evaluation only: the fit sees the recordings, never the truth; this example
//! reads the truth afterwards to measure the prediction.
//!
//! ```sh
//! cargo run --release -p experiments --example switch_on_truth -- [--seed 1] [--sessions 6] [--scale 5] \
//!     [--effect thermal_lag] [--unit physical|paper_exact]
//! ```
//!
//! One unit's campaign is simulated as the closed-loop experiment simulates it and its loop closed
//! (which fits the switch-on rate on the calibration activations, `drift_diagnose::switch_on_rate`);
//! every activation's predicted start is then compared with the true rate at switch-on, °C/s:
//! the sensor site's (where a sensor-rate filter starts: heating less cooling) and the element's
//! (where an element-rate filter starts: its cooling, the element not heating yet), each over the
//! first 10-ms step of the simulator's thermal grid. Grouped by protocol or field and by the
//! off-time before: the calibration's shortest off-time is 1 min, the field's 30 s. A paper-exact
//! unit's bias follows the sensor's site, so its element columns are left empty.

use anyhow::Context;
use drift_diagnose::closing::{close, LoopOptions};
use drift_diagnose::roles::Roles;
use drift_diagnose::switch_on_rate::{start_rates, switch_ons};
use drift_evaluate::evaluate::switch_on_raw;
use drift_fit::analyse::analyse;
use drift_fit::{fit_unit, FitSettings};
use drift_recording::{read_recording, SeriesKind, AUX_RATE_HZ, TRUTH_DIR, TRUTH_EXTENSION};
use drift_sim::truth::read_truth;
use drift_sim::{simulate_campaign, UnitModel};
use experiments::closed_loop::{campaign, Plan};

/// Off-time bins, s: below the calibration's shortest off-time, then as the profile groups them.
const OFF_BINS_S: [(f64, f64); 5] = [
    (0.0, 60.0),
    (60.0, 90.0),
    (90.0, 300.0),
    (300.0, 900.0),
    (900.0, f64::INFINITY),
];

/// One activation's axis: the predicted and the true rate at switch-on, °C/s.
struct Start {
    field: bool,
    off_s: f64,
    axis: usize,
    residual_heat: f64,
    predicted_sensor: f64,
    true_sensor: f64,
    predicted_element: f64,
    true_element: f64,
}

fn mean_sd(values: &[f64]) -> (f64, f64) {
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    (mean, var.sqrt())
}

/// The predicted start of the rate filter against the simulator's truth.
#[derive(clap::Parser)]
struct Args {
    /// The campaign's seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Field sessions per set point.
    #[arg(long, default_value_t = 6)]
    sessions: u32,
    /// The hidden effect's magnitude, times the simulator's default.
    #[arg(long, default_value_t = 5.0)]
    scale: f64,
    /// The hidden effect (`none` for none).
    #[arg(long, default_value = "thermal_lag")]
    effect: String,
    /// The unit: `physical` or `paper_exact`.
    #[arg(long, default_value = "physical", value_parser = ["physical", "paper_exact"])]
    unit: String,
}

fn main() -> anyhow::Result<()> {
    let Args {
        seed,
        sessions,
        scale,
        effect,
        unit,
    } = clap::Parser::parse();
    let plan = Plan {
        sessions,
        scale,
        unit: if unit == "paper_exact" {
            UnitModel::PaperExact
        } else {
            UnitModel::Physical
        },
        ..Plan::default()
    };
    plan.check()?;

    let work = tempfile::tempdir()?;
    let dir = work.path().join("campaign");
    simulate_campaign(&campaign(seed, &effect, plan.unit, &plan)?, &dir, |_| {})?;
    // Each recording with its truth sidecar, activation by activation.
    let mut segments = Vec::new();
    let mut truths = Vec::new();
    for path in drift_evaluate::pipeline::recording_files(&dir)? {
        let stem = path
            .file_stem()
            .context("a recording without a name")?
            .to_string_lossy()
            .into_owned();
        let truth = read_truth(
            &dir.join(TRUTH_DIR)
                .join(format!("{stem}.{TRUTH_EXTENSION}")),
        )?;
        let recording = read_recording(&path)?;
        anyhow::ensure!(
            truth.len() == recording.segments.len(),
            "{}: {} activations but {} in its truth",
            path.display(),
            recording.segments.len(),
            truth.len()
        );
        segments.extend(recording.segments);
        truths.extend(truth);
    }

    // The fit, on the recordings only.
    let settings = FitSettings::default();
    let calibration = Roles::split(&segments, &plan.calibration).calibration;
    let analysed = calibration
        .iter()
        .map(|s| analyse(s, &settings))
        .collect::<Result<Vec<_>, _>>()?;
    let fitted = fit_unit(&analysed, &settings)?;
    let options = LoopOptions {
        clock: plan.clock,
        ..LoopOptions::new(&plan.calibration)
    };
    let closed = close(
        &fitted,
        &segments,
        &[],
        &options,
        &settings,
        drift_recording::QUIET,
    )?;
    let core = &fitted.modified.settings;
    let fits = &closed.switch_on_rate;
    for fit in fits {
        println!(
            "{}: heating {:.4} °C/s ({} cold starts) less residual heat × ({:.5} + {:.5} · remaining)/s ({} warm starts)",
            fit.axis,
            fit.rate.heating_celsius_per_s,
            fit.cold_starts,
            fit.rate.cooling_per_second,
            fit.rate.cooling_per_second_per_remaining,
            fit.warm_starts
        );
    }
    let rates = fits.clone().map(|fit| fit.rate);

    // Afterwards, the truth.
    let grid_s = 1.0 / f64::from(AUX_RATE_HZ);
    let mut starts = Vec::new();
    for (segment, truth) in segments.iter().zip(&truths) {
        let kept = closed.keying.kept(segment);
        let raw = switch_on_raw(segment, &settings);
        let on = switch_ons(core, raw, Some(kept));
        let predicted = start_rates(&rates, core, raw, Some(kept));
        let first_step = |series: &[f32]| match series {
            [a, b, ..] => f64::from(b - a) / grid_s,
            _ => f64::NAN,
        };
        for (axis, on) in on.iter().enumerate() {
            starts.push(Start {
                field: segment.labels.series_kind == SeriesKind::Field,
                off_s: segment.labels.off_before_s.unwrap_or(f64::INFINITY),
                axis,
                residual_heat: f64::from(on.residual_heat_celsius),
                predicted_sensor: f64::from(predicted.sensor[axis]),
                true_sensor: first_step(&truth.asic_celsius[axis]),
                predicted_element: f64::from(predicted.element[axis]),
                true_element: first_step(&truth.element_celsius[axis]),
            });
        }
    }

    println!();
    println!("| activations | off before | axis | n | residual heat °C | sensor: predicted | true | error mean (sd) | element: predicted | true | error mean (sd) |");
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for field in [false, true] {
        for (low, high) in OFF_BINS_S {
            for axis in 0..3 {
                let of: Vec<&Start> = starts
                    .iter()
                    .filter(|s| s.field == field && s.axis == axis)
                    .filter(|s| s.off_s >= low && s.off_s < high)
                    .collect();
                if of.is_empty() {
                    continue;
                }
                let column = |f: &dyn Fn(&Start) -> f64| {
                    mean_sd(&of.iter().map(|s| f(s)).collect::<Vec<_>>())
                };
                let (heat, _) = column(&|s| s.residual_heat);
                let (sensor, _) = column(&|s| s.predicted_sensor);
                let (true_sensor, _) = column(&|s| s.true_sensor);
                let sensor_error = column(&|s| s.predicted_sensor - s.true_sensor);
                let element = if plan.unit == UnitModel::PaperExact {
                    "– | – | –".to_owned()
                } else {
                    let (predicted, _) = column(&|s| s.predicted_element);
                    let (truth, _) = column(&|s| s.true_element);
                    let (mean, sd) = column(&|s| s.predicted_element - s.true_element);
                    format!("{predicted:.4} | {truth:.4} | {mean:+.4} ({sd:.4})")
                };
                let off = if high.is_finite() {
                    format!("{low:.0}–{high:.0} s")
                } else {
                    format!("≥ {low:.0} s")
                };
                println!(
                    "| {} | {off} | {} | {} | {heat:.2} | {sensor:.4} | {true_sensor:.4} | {:+.4} ({:.4}) | {element} |",
                    if field { "field" } else { "protocol" },
                    ["X", "Y", "Z"][axis],
                    of.len(),
                    sensor_error.0,
                    sensor_error.1,
                );
            }
        }
    }
    Ok(())
}
