//! What stage 3's history lookup costs: each protocol activation at a calibration set point is
//! corrected twice with curves from the *other* repeats — once the paper's way (the curve found by
//! the activation's rise, `k` interpolated by rise between the two curves that bracket it) and
//! once by an oracle that knows the activation's history and takes its own curve's `k`. Both are
//! the same f64 arithmetic on the same 10-ms analysis grid, from the first reference time (2 s) on,
//! so their difference is the lookup alone; the drift metric is max − min of what is left.
//!
//! ```sh
//! cargo run --release -p experiments --example stage3_oracle -- <campaign dir> [calibration set points, default 30,40]
//! ```
//!
//! Then the calibration curves themselves (axis X, rise and `k` at 5 and 20 s, switch-on
//! temperature), which show whether a warmer start rises less.
//!
//! When the two columns agree, the rise identifies the history as the paper assumes; when the
//! paper's column is larger, the curves cross (`drift_fit::history_order`) and the difference is
//! what an input that names the history (the off-time) would recover. Numbers in experiments/README.md.

use std::collections::BTreeMap;
use std::path::Path;

use drift_evaluate::pipeline::{recording_files, run, Options};
use drift_fit::analyse::Analysed;
use drift_fit::curves::CurveKey;
use drift_fit::FitSettings;

/// Mean drift/rise ratio and mean rise of a group of activations at grid index `i`.
fn point(members: &[&Analysed], axis: usize, i: usize) -> (f64, f64) {
    let n = members.len() as f64;
    let rise = members
        .iter()
        .map(|m| f64::from(m.rise_celsius[axis][i]))
        .sum::<f64>()
        / n;
    let drift = members
        .iter()
        .map(|m| f64::from(m.drift_dps[axis][i]))
        .sum::<f64>()
        / n;
    (rise, drift / rise)
}

/// `k` the paper's way: among the curves' points sorted by rise, interpolate by `rise`, clamped.
fn k_by_rise(points: &mut [(f64, f64)], rise: f64) -> f64 {
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (first, last) = (points[0], points[points.len() - 1]);
    if rise <= first.0 {
        return first.1;
    }
    if rise >= last.0 {
        return last.1;
    }
    let j = points.iter().rposition(|p| p.0 <= rise).unwrap_or(0);
    let (lo, hi) = (points[j], points[j + 1]);
    lo.1 + (hi.1 - lo.1) * (rise - lo.0) / (hi.0 - lo.0)
}

/// Per (unit, set point in m°C): summed drift with `k` by rise and by own history, per axis, and
/// how many activations.
type Sums = ([f64; 3], [f64; 3], usize);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .ok_or("usage: stage3_oracle <campaign dir> [30,40]")?;
    let calibration: Vec<f64> = match args.next() {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![30.0, 40.0],
    };
    let options = Options {
        calibration_set_points: calibration,
        validation_set_points: vec![],
        fit: FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    };
    let files = recording_files(Path::new(&dir))?;
    let outcome = run(&files, &options, false, drift_recording::QUIET)?;
    for unit in &outcome.fitted {
        for note in unit.notes.iter().filter(|n| n.contains("stage 3")) {
            println!("{}: {note}", unit.unit_id);
        }
    }
    let first = (options.fit.first_reference_s * 1000.0 / f64::from(options.fit.grid_ms)) as usize;
    let mut sums: BTreeMap<(String, i64), Sums> = BTreeMap::new();
    let all = &outcome.calibration;
    for activation in all {
        let Some(key) = CurveKey::of(activation, &options.fit) else {
            continue;
        };
        let labels = &activation.labels;
        let same_set_point = |b: &&Analysed| {
            b.labels.unit_id == labels.unit_id
                && (b.labels.set_point_celsius - labels.set_point_celsius).abs() < 1e-6
        };
        let mut curves: BTreeMap<CurveKey, Vec<&Analysed>> = BTreeMap::new();
        for other in all
            .iter()
            .filter(same_set_point)
            .filter(|b| b.labels.repeat != labels.repeat)
        {
            if let Some(k) = CurveKey::of(other, &options.fit) {
                curves.entry(k).or_default().push(other);
            }
        }
        let Some(own) = curves.get(&key) else {
            continue;
        };
        let len = curves
            .values()
            .flatten()
            .map(|m| m.len())
            .min()
            .unwrap_or(0)
            .min(activation.len());
        let entry = sums
            .entry((
                labels.unit_id.clone(),
                (labels.set_point_celsius * 1000.0).round() as i64,
            ))
            .or_insert(([0.0; 3], [0.0; 3], 0));
        for axis in 0..3 {
            let (mut by_rise, mut by_history) = (Vec::new(), Vec::new());
            for i in first..len {
                let rise = f64::from(activation.rise_celsius[axis][i]);
                let drift = f64::from(activation.drift_dps[axis][i]);
                let mut points: Vec<(f64, f64)> =
                    curves.values().map(|m| point(m, axis, i)).collect();
                by_rise.push(drift - k_by_rise(&mut points, rise) * rise);
                by_history.push(drift - point(own, axis, i).1 * rise);
            }
            let span = |v: &[f64]| {
                v.iter().copied().fold(f64::MIN, f64::max)
                    - v.iter().copied().fold(f64::MAX, f64::min)
            };
            entry.0[axis] += span(&by_rise);
            entry.1[axis] += span(&by_history);
        }
        entry.2 += 1;
    }
    println!("| unit | set point | activations | drift, k by rise (paper) X / Y / Z | drift, k of own history (oracle) X / Y / Z |");
    println!("|---|---:|---:|---|---|");
    for ((unit, set_point), (by_rise, by_history, n)) in sums {
        let mean = |v: [f64; 3]| v.map(|s| format!("{:.4}", s / n as f64)).join(" / ");
        println!(
            "| {unit} | {:+.1} °C | {n} | {} | {} |",
            set_point as f64 / 1000.0,
            mean(by_rise),
            mean(by_history)
        );
    }
    print_curves(&outcome.fitted);
    Ok(())
}

/// The averaged calibration curves on axis X at 5 and 20 s: whether a warmer start rises less.
fn print_curves(fitted: &[drift_fit::FittedUnit]) {
    const AXIS: usize = 0;
    println!(
        "\n| unit | set point | curve | switched on at | rise 5 s | k 5 s | rise 20 s | k 20 s |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    for unit in fitted {
        for sp in &unit.set_points {
            for curve in &sp.curves {
                let at = |s: u32| {
                    let i = (s * 1000 / sp.grid_ms) as usize;
                    let rise = curve.rise_celsius[AXIS].get(i).copied().unwrap_or(f64::NAN);
                    let drift = curve.drift_dps[AXIS].get(i).copied().unwrap_or(f64::NAN);
                    format!("{rise:.3} | {:.5}", drift / rise)
                };
                println!(
                    "| {} | {:+.1} °C | {} | {:.2} | {} | {} |",
                    unit.unit_id,
                    sp.set_point_celsius,
                    curve.key.name(),
                    curve.switch_on_celsius[AXIS],
                    at(5),
                    at(20)
                );
            }
        }
    }
}
