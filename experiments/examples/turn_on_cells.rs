//! Is the recommended model's excess over the best baseline in a cell more than its activations'
//! scatter? The report's evaluation (held-out repeats, the validation set point, field sessions) is
//! run, and in every unit × axis × set point × activation class cell where the recommended model's
//! mean residual bias RMS is above the best baseline's (the lowest mean of standard, 3rd-order,
//! relative and relative cubic, as the report picks it), the per-activation difference
//! `recommended − that baseline` is bootstrapped over the cell's activations (resampled with
//! replacement, 10 000 times): its mean and a 95 % percentile interval. A cell whose interval holds
//! 0 is not distinguishable from the baseline on these activations.
//!
//! ```sh
//! cargo run --release -p experiments --example turn_on_cells -- <campaign dir> [30,40] [33]
//! ```

use std::path::Path;

use anyhow::Context;
use drift_evaluate::evaluate::{ActivationResult, ModelKind};
use drift_evaluate::pipeline::{recording_files, run, Options};
use drift_evaluate::summary::cells;
use drift_fit::FitSettings;

/// Resamples per cell.
const RESAMPLES: usize = 10_000;

/// A small deterministic generator (SplitMix64): the interval is the same on every run.
struct SplitMix(u64);

impl SplitMix {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z % n as u64) as usize
    }
}

/// Mean and 95 % percentile interval of the mean of `d`, bootstrapped.
fn bootstrap(d: &[f64], rng: &mut SplitMix) -> (f64, f64, f64) {
    let n = d.len();
    let mean = d.iter().sum::<f64>() / n as f64;
    let mut means: Vec<f64> = (0..RESAMPLES)
        .map(|_| (0..n).map(|_| d[rng.below(n)]).sum::<f64>() / n as f64)
        .collect();
    means.sort_by(f64::total_cmp);
    let at = |q: f64| means[((RESAMPLES as f64 - 1.0) * q).round() as usize];
    (mean, at(0.025), at(0.975))
}

fn list(text: &str) -> anyhow::Result<Vec<f64>> {
    Ok(text.split(',').map(str::parse).collect::<Result<_, _>>()?)
}

fn rms(r: &ActivationResult, model: ModelKind, axis: usize) -> Option<f64> {
    r.models
        .iter()
        .find(|m| m.model == model)
        .map(|m| m.residual_rms_dps[axis])
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .context("usage: turn_on_cells <campaign dir> [30,40] [33]")?;
    let calibration = args.next().map_or(Ok(vec![30.0, 40.0]), |t| list(&t))?;
    let validation = args.next().map_or(Ok(vec![33.0]), |t| list(&t))?;
    let settings = FitSettings::default();
    let options = Options {
        calibration_set_points: calibration,
        validation_set_points: validation,
        fit: settings.clone(),
        held_out_repeats: true,
        evaluate: true,
        switch_on_ambient: None,
    };
    let files = recording_files(Path::new(&dir))?;
    let outcome = run(&files, &options, false, drift_recording::QUIET)?;
    let cells = cells(&outcome.results, settings.independent_after_min);
    let mut rng = SplitMix(1);
    let (mut above, mut distinguishable) = (0, 0);
    println!("| unit | set point | class | axis | activations | recommended | best baseline | ratio | excess (°/s) | 95 % interval |");
    println!("|---|---:|---|---|---:|---:|---:|---:|---:|---|");
    for ((unit, set_point, class, axis), members) in &cells {
        let mean = |model| {
            members
                .iter()
                .filter_map(|r| rms(r, model, *axis))
                .sum::<f64>()
                / members.len() as f64
        };
        let Some((best, best_mean)) = ModelKind::BASELINES
            .iter()
            .map(|&b| (b, mean(b)))
            .filter(|(_, m)| m.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            continue;
        };
        let recommended = mean(ModelKind::Recommended);
        if recommended <= best_mean {
            continue;
        }
        above += 1;
        let d: Vec<f64> = members
            .iter()
            .filter_map(|r| Some(rms(r, ModelKind::Recommended, *axis)? - rms(r, best, *axis)?))
            .collect();
        let (excess, low, high) = bootstrap(&d, &mut rng);
        if low > 0.0 {
            distinguishable += 1;
        }
        println!(
            "| {unit} | {:+.0} °C | {} | {} | {} | {recommended:.4} | {best_mean:.4} ({}) | {:.2} | {excess:+.4} | {low:+.4} … {high:+.4} |",
            *set_point as f64 / 1000.0,
            class.name(),
            ["X", "Y", "Z"][*axis],
            members.len(),
            best.name(),
            recommended / best_mean,
        );
    }
    println!();
    println!(
        "{above} of {} cells above the best baseline; {distinguishable} of them with the 95 % interval above 0",
        cells.len()
    );
    Ok(())
}
