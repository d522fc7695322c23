//! Where the fit's time goes, phase by phase, in pure Rust (no Python, no file reading in the timed
//! part): the profiling aid behind docs/performance.md's fit rows.
//!
//! Reads the +30/+40 °C protocol recordings of a campaign folder into memory (untimed), then times,
//! best of `repeats`: the analysis one activation after another on one thread, the analysis on
//! rayon's threads, and for each unit the fit's phases (grouping and averaging the curves, the
//! reference times of the three axes, the baselines) and `fit_unit` as a whole; finally the whole
//! fit from segments as `gyrodrift.fit(segments)` runs it. Usage:
//!
//! ```text
//! cargo run --release -p experiments --example fit_phases -- <campaign folder> [repeats] [analyse|fit]
//! ```
//!
//! For a profile, run it under `perf record` (the release profile keeps line tables); the last
//! argument keeps only the single-thread analysis or only the fit's phases.

use std::time::Instant;

use anyhow::{Context, Result};
use drift_evaluate::pipeline::{self, calibration_segment, Options};
use drift_fit::analyse::{analyse, Analysed};
use drift_fit::curves::{group, CurveKey};
use drift_fit::knots::choose;
use drift_fit::{baselines, fit_unit, FitSettings};
use drift_recording::read_recording;
use rayon::prelude::*;

/// This thread's time on a CPU so far, s (Linux; 0 elsewhere): steadier than wall time on a
/// shared machine, for the phases that run on this thread.
fn on_cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// Best wall time and best on-CPU time of this thread over `repeats` runs, and the last result.
fn best<T>(repeats: usize, mut run: impl FnMut() -> T) -> ((f64, f64), T) {
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    let mut result = None;
    for _ in 0..repeats.max(1) {
        let (started, on_cpu) = (Instant::now(), on_cpu_s());
        result = Some(run());
        wall = wall.min(started.elapsed().as_secs_f64());
        cpu = cpu.min(on_cpu_s() - on_cpu);
    }
    ((wall, cpu), result.expect("at least one run"))
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let folder = args
        .next()
        .context("usage: fit_phases <campaign folder> [repeats]")?;
    let repeats: usize = args.next().map_or(Ok(5), |r| r.parse())?;
    let only = args.next();
    let run = |phase: &str| only.as_deref().is_none_or(|o| o == phase);
    let options = Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: Vec::new(),
        fit: FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    };
    let settings = &options.fit;
    let mut segments = Vec::new();
    for path in pipeline::recording_files(folder.as_ref())? {
        if pipeline::calibration_file(&path, &options)? == Some(false) {
            continue;
        }
        let recording = read_recording(&path)?;
        segments.extend(
            recording
                .segments
                .into_iter()
                .filter(|s| calibration_segment(s, &options)),
        );
    }
    let samples: usize = segments.iter().map(|s| s.len()).sum();
    println!(
        "{} activations, {:.1} M samples, {} rayon threads, best of {repeats}",
        segments.len(),
        samples as f64 / 1e6,
        rayon::current_num_threads()
    );
    println!("     wall  this thread on CPU");
    let row = |what: &str, (wall, cpu): (f64, f64)| {
        if wall < 0.01 {
            println!("{:9.1} µs {:9.1} µs  {what}", wall * 1e6, cpu * 1e6);
        } else {
            println!("{wall:9.4} s {cpu:9.4} s  {what}");
        }
    };

    if run("memory") {
        // The floor of any analysis: reading every sample once (integer sums, vectorised).
        let (s, _) = best(repeats, || {
            let total = segments
                .iter()
                .map(|s| {
                    let t: i64 = s
                        .temperature_raw
                        .iter()
                        .flatten()
                        .map(|&r| i64::from(r))
                        .sum();
                    let r: u64 = s
                        .rate_dps
                        .iter()
                        .flatten()
                        .map(|&r| u64::from(r.to_bits()))
                        .sum();
                    t.wrapping_add(r as i64)
                })
                .fold(0_i64, i64::wrapping_add);
            std::hint::black_box(total)
        });
        row("read every sample once", s);
    }
    if run("one") {
        // The analysis of one activation, the fastest of many runs: short enough to run between
        // two preemptions, so steady on a shared machine (for comparing code changes).
        let (s, _) = best(repeats * 100, || analyse(&segments[0], settings));
        row("analyse one activation (fastest run)", s);
    }
    if run("analyse") {
        let (s, _) = best(repeats, || {
            segments
                .iter()
                .map(|s| analyse(s, settings))
                .collect::<Result<Vec<_>, _>>()
        });
        row("analyse, one thread", s);
    }
    if !run("fit") {
        return Ok(());
    }
    let (s, analysed) = best(repeats, || {
        segments
            .par_iter()
            .map(|s| analyse(s, settings))
            .collect::<Result<Vec<Analysed>, _>>()
    });
    row("analyse, rayon", s);
    let analysed = analysed?;
    let mut units: Vec<&str> = analysed.iter().map(|a| a.labels.unit_id.as_str()).collect();
    units.dedup();
    for unit in units {
        let activations: Vec<Analysed> = analysed
            .iter()
            .filter(|a| a.labels.unit_id == unit)
            .cloned()
            .collect();
        let (s, set_points) = best(repeats, || group(&activations, settings));
        row(&format!("{unit}: group and average the curves"), s);
        let first = (settings.first_reference_s * 1000.0 / f64::from(settings.grid_ms)).round();
        let (s, _) = best(repeats, || {
            (0..3)
                .map(|axis| {
                    choose(
                        &set_points,
                        axis,
                        first as usize,
                        settings.reference_count,
                        settings.reference_window_points,
                    )
                })
                .collect::<Vec<_>>()
        });
        row(&format!("{unit}: reference times, three axes"), s);
        let protocol: Vec<&Analysed> = activations
            .iter()
            .filter(|a| CurveKey::of(a, settings).is_some())
            .collect();
        let by_set_point: Vec<Vec<&Analysed>> = set_points
            .iter()
            .map(|sp| {
                protocol
                    .iter()
                    .copied()
                    .filter(|a| (a.labels.set_point_celsius - sp.set_point_celsius).abs() < 1e-6)
                    .collect()
            })
            .collect();
        let core = drift_core::Settings::default();
        let (s, _) = best(repeats, || baselines::standard(&by_set_point, core));
        row(&format!("{unit}: standard baseline"), s);
        let (s, _) = best(repeats, || {
            baselines::least_squares_polynomial(&protocol, settings.polynomial_degree, core)
        });
        row(&format!("{unit}: least-squares baseline"), s);
        let (s, _) = best(repeats, || fit_unit(&activations, settings));
        row(&format!("{unit}: fit_unit"), s);
    }
    let (s, _) = best(repeats, || {
        let analysed = segments
            .par_iter()
            .map(|s| analyse(s, settings))
            .collect::<Result<Vec<Analysed>, _>>()?;
        let mut by_unit = std::collections::BTreeMap::<String, Vec<Analysed>>::new();
        for a in analysed {
            by_unit.entry(a.labels.unit_id.clone()).or_default().push(a);
        }
        let units: Vec<&Vec<Analysed>> = by_unit.values().collect();
        units
            .par_iter()
            .map(|activations| fit_unit(activations, settings))
            .collect::<Result<Vec<_>, _>>()
    });
    row("whole fit from segments (analyse + fit every unit)", s);
    Ok(())
}
