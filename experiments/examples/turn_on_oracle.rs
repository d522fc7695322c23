//! What limits the recommended model's residual bias in field-like use: its switch-on offset or
//! the drift after it. The tables are fitted on the calibration set points' protocol activations
//! (recordings only); afterwards every field activation is corrected with the recommended model
//! and the residual bias RMS (1-s low-passed corrected rate) is measured six ways:
//!
//! - *as fitted*: the recommended model as firmware runs it (started from what it kept of the
//!   previous activation);
//! - *true offset*: the same drift correction started from the simulator's true bias at switch-on
//!   (an oracle: what a perfect switch-on offset model would leave);
//! - *best constant*: the same drift correction with the one offset that minimises the
//!   activation's RMS (what no switch-on offset model can beat);
//! - *standard's offset*: the same drift correction started from the standard baseline's bias at
//!   the switch-on temperature (a fitter-legal hybrid);
//! - *residual heat not held* and *no residual-heat term*: the turn-on bias `q(T_on)` with the
//!   residual heat's share taken however large, and without it;
//! - *fair oracle*: the recommended model's offset corrected by the best prediction from what the
//!   instrument knows at switch-on — a least-squares line of each activation's offset error (the
//!   mean of its low-passed corrected rate: measurable on a static unit, not the simulator's
//!   truth) in the switch-on temperature and the estimated residual heat, fitted per cell on the
//!   cell's other activations (leave one out) and, optimistically, on all of them (in sample).
//!
//! Each is a mean over a unit × axis × set point cell's field activations, set beside the best
//! baseline's (the lowest of standard, 3rd-order, relative and relative cubic in that cell), and
//! the cells where it is at or below the best baseline are counted.
//!
//! ```sh
//! cargo run --release -p experiments --example turn_on_oracle -- <campaign dir> [30,40]
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use drift_evaluate::evaluate::{
    correct_segment, correct_segment_after, evaluate_after, kept_before, switch_on_raw, ModelKind,
};
use drift_evaluate::pipeline::{recording_files, run, Options};
use drift_fit::lowpass::centred_moving_average;
use drift_fit::FitSettings;
use drift_recording::{read_recording, SeriesKind, TRUTH_DIR, TRUTH_EXTENSION};
use drift_sim::truth::read_truth;

/// The variants measured, in column order.
const VARIANTS: [&str; 10] = [
    "as fitted",
    "true offset",
    "best constant",
    "standard's offset",
    "residual heat not held",
    "no residual-heat term",
    "fair oracle, leave one out",
    "fair oracle, in sample",
    "modified",
    "best baseline",
];

/// Columns of the fair oracles, filled after every activation of a cell is seen.
const FAIR_LOO: usize = 6;
const FAIR_IN_SAMPLE: usize = 7;

/// One field activation × axis, kept for the fair oracles: the low-passed corrected rate, its
/// mean (the offset error), the switch-on temperature and the residual heat estimated.
struct Kept {
    low: Vec<f64>,
    offset: f64,
    on: f64,
    heat: f64,
}

/// Least squares of `y` on `[1, on, heat]` over `rows` (ridge-stabilised: a cell whose residual
/// heats are all equal has a singular system), by Cramer's rule on the 3×3 normal equations.
fn line(rows: &[&Kept]) -> [f64; 3] {
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for k in rows {
        let phi = [1.0, k.on, k.heat];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += phi[i] * phi[j];
            }
            b[i] += phi[i] * k.offset;
        }
    }
    for (i, row) in a.iter_mut().enumerate().skip(1) {
        row[i] += 1e-6 * rows.len() as f64;
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&a);
    let mut c = [0.0; 3];
    for (k, value) in c.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *value = det(&m) / d;
    }
    c
}

/// RMS of `low − prediction(k)`.
fn shifted(k: &Kept, c: [f64; 3]) -> f64 {
    let p = c[0] + c[1] * k.on + c[2] * k.heat;
    (k.low.iter().map(|v| (v - p).powi(2)).sum::<f64>() / k.low.len().max(1) as f64).sqrt()
}

/// RMS of the low-passed `rate + shift`.
fn rms(rate: &[f32], shift: f64, window: usize) -> f64 {
    let low = centred_moving_average(rate, window);
    (low.iter().map(|v| (v + shift).powi(2)).sum::<f64>() / low.len().max(1) as f64).sqrt()
}

/// Standard deviation of the low-passed `rate` (the RMS after its best constant offset).
fn sd(rate: &[f32], window: usize) -> f64 {
    let low = centred_moving_average(rate, window);
    let n = low.len().max(1) as f64;
    let mean = low.iter().sum::<f64>() / n;
    (low.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt()
}

/// Per cell (unit, set point m°C, axis): per variant the summed RMS, each baseline's summed RMS,
/// and the count.
type Cells = BTreeMap<(String, i64, usize), ([f64; VARIANTS.len()], [f64; 4], usize)>;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .context("usage: turn_on_oracle <campaign dir> [30,40]")?;
    let calibration: Vec<f64> = match args.next() {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => vec![30.0, 40.0],
    };
    let settings = FitSettings::default();
    let options = Options {
        calibration_set_points: calibration,
        validation_set_points: vec![],
        fit: settings.clone(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    };
    let dir = Path::new(&dir);
    let files = recording_files(dir)?;
    let outcome = run(&files, &options, false, drift_recording::QUIET)?;
    let baselines = [
        ModelKind::Standard,
        ModelKind::ThirdOrder,
        ModelKind::Relative,
        ModelKind::RelativeCubic,
    ];
    let mut cells: Cells = BTreeMap::new();
    let mut kept_rows: BTreeMap<(String, i64, usize), Vec<Kept>> = BTreeMap::new();
    let mut offsets: Vec<(f64, f64, f64)> = Vec::new();
    for path in &files {
        let recording = read_recording(path)?;
        let Some(fitted) = outcome
            .fitted
            .iter()
            .find(|f| f.unit_id == recording.unit_id)
        else {
            continue;
        };
        let stem = path
            .file_stem()
            .context("a recording without a name")?
            .to_string_lossy()
            .into_owned();
        let truth = read_truth(
            &dir.join(TRUTH_DIR)
                .join(format!("{stem}.{TRUTH_EXTENSION}")),
        )?;
        anyhow::ensure!(truth.len() == recording.segments.len());
        let segments: Vec<_> = recording.segments.iter().collect();
        let kept = kept_before(&segments, &settings, &fitted.by_history.settings, true);
        for ((segment, truth), previous) in segments.iter().zip(&truth).zip(&kept) {
            if segment.labels.series_kind != SeriesKind::Field {
                continue;
            }
            let window = settings.lowpass_window(segment.sample_rate_hz);
            let switch_on = switch_on_raw(segment, &settings);
            let result = evaluate_after(fitted, segment, &settings, previous);
            let (recommended, _) =
                correct_segment_after(&fitted.recommended, segment, switch_on, Some(previous));
            let (standard, _) = correct_segment(&fitted.standard, segment, switch_on);
            let set_point = (segment.labels.nominal_set_point_celsius() * 1000.0).round() as i64;
            let core = &fitted.recommended.settings;
            for axis in 0..3 {
                let rate = &segment.rate_dps[axis];
                let rec = &recommended[axis];
                // The model's bias at the first sample is raw − corrected there.
                let model_on = f64::from(rate[0]) - f64::from(rec[0]);
                let standard_on = f64::from(rate[0]) - f64::from(standard[axis][0]);
                let true_on = f64::from(truth.systematic_bias_dps[axis][0]);
                offsets.push((true_on, model_on, standard_on));
                let on = core.celsius(switch_on[axis]);
                let estimate = drift_core::SwitchOn::estimate(on, Some(previous[axis]));
                let turn_on = &fitted.recommended.axes[axis].turn_on;
                let (q, _) = turn_on
                    .polynomial
                    .continued(on, core.ambient_margin_celsius);
                let q = f64::from(q);
                let residual = if estimate.known {
                    f64::from(estimate.residual_heat_celsius).max(0.0)
                } else {
                    0.0
                };
                let slope = f64::from(turn_on.dps_per_residual_celsius);
                let heat = slope * residual;
                let of = |kind: ModelKind| {
                    result
                        .models
                        .iter()
                        .find(|m| m.model == kind)
                        .map_or(f64::NAN, |m| m.residual_rms_dps[axis])
                };
                let values = [
                    rms(rec, 0.0, window),
                    rms(rec, model_on - true_on, window),
                    sd(rec, window),
                    rms(rec, model_on - standard_on, window),
                    rms(rec, model_on - q - heat, window),
                    rms(rec, model_on - q, window),
                    0.0,
                    0.0,
                    of(ModelKind::Modified),
                    0.0,
                ];
                let low = centred_moving_average(rec, window);
                let offset = low.iter().sum::<f64>() / low.len().max(1) as f64;
                kept_rows
                    .entry((recording.unit_id.clone(), set_point, axis))
                    .or_default()
                    .push(Kept {
                        low,
                        offset,
                        on: f64::from(on),
                        heat: residual,
                    });
                let entry = cells
                    .entry((recording.unit_id.clone(), set_point, axis))
                    .or_insert(([0.0; VARIANTS.len()], [0.0; 4], 0));
                for (sum, v) in entry.0.iter_mut().zip(values) {
                    *sum += v;
                }
                for (sum, kind) in entry.1.iter_mut().zip(baselines) {
                    *sum += of(kind);
                }
                entry.2 += 1;
            }
        }
    }
    let mut rows = Vec::new();
    for (key, (sums, _, _)) in &mut cells {
        let members: Vec<&Kept> = kept_rows
            .get(key)
            .map_or(Vec::new(), |v| v.iter().collect());
        let all = line(&members);
        for (i, k) in members.iter().enumerate() {
            let others: Vec<&Kept> = members
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, k)| *k)
                .collect();
            sums[FAIR_LOO] += shifted(k, line(&others));
            sums[FAIR_IN_SAMPLE] += shifted(k, all);
        }
    }
    for ((unit, set_point, axis), (sums, baseline_sums, n)) in &cells {
        let best = baseline_sums.iter().fold(f64::INFINITY, |b, s| b.min(*s)) / *n as f64;
        let mut means = sums.map(|s| s / *n as f64);
        means[VARIANTS.len() - 1] = best;
        rows.push((unit.clone(), *set_point, *axis, *n, means));
    }
    println!(
        "| unit | set point | axis | activations | {} |",
        VARIANTS.join(" | ")
    );
    println!("|---|---:|---|---:|{}", "---:|".repeat(VARIANTS.len()));
    for (unit, set_point, axis, n, means) in &rows {
        println!(
            "| {unit} | {:+.0} °C | {} | {n} | {} |",
            *set_point as f64 / 1000.0,
            ["X", "Y", "Z"][*axis],
            means.map(|m| format!("{m:.4}")).join(" | ")
        );
    }
    let count = |v: usize| {
        rows.iter()
            .filter(|r| r.4[v] <= r.4[VARIANTS.len() - 1])
            .count()
    };
    let mean = |v: usize| rows.iter().map(|r| r.4[v]).sum::<f64>() / rows.len().max(1) as f64;
    println!();
    println!("| variant | mean over cells (°/s) | cells at or below the best baseline |");
    println!("|---|---:|---:|");
    for (v, name) in VARIANTS.iter().enumerate() {
        println!(
            "| {name} | {:.4} | {} of {} |",
            mean(v),
            count(v),
            rows.len()
        );
    }
    let n = offsets.len().max(1) as f64;
    let rms_of = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
        (offsets.iter().map(|o| f(o).powi(2)).sum::<f64>() / n).sqrt()
    };
    println!();
    println!(
        "switch-on offset error RMS over {} field activation-axes: recommended {:.4}, standard {:.4} °/s",
        offsets.len(),
        rms_of(&|o| o.1 - o.0),
        rms_of(&|o| o.2 - o.0)
    );
    Ok(())
}
