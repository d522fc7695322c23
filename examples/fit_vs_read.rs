//! `gyrodrift fit`'s work against reading the same recordings, wall and CPU time, alternated in one
//! process so that the machine's load weighs on both alike.
//!
//! On a machine whose cores other work keeps busy the fit's second thread gets little time of its
//! own, and the wall-time ratio of `benches/fit.rs` tends to the ratio of CPU time printed here.
//! Usage: `cargo run --release --example fit_vs_read -- <campaign folder> [rounds]` on a simulated
//! campaign (`gyrodrift simulate -o <folder> --truth-at-aux-rate`); the fit's options are
//! `gyrodrift fit`'s defaults (+30/+40 °C). Prints one line per run:
//!
//! ```text
//! <read_only|read_analyse_fit> <wall s> <CPU s (user + system, every thread)> <samples>
//! ```

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use drift_evaluate::pipeline::{self, Options};
use drift_recording::OpenRecording;

/// The process's CPU time (user + system, all threads), s: Linux's `/proc/self/stat`, in clock
/// ticks of 1/100 s (std has no `getrusage`).
fn cpu_seconds() -> anyhow::Result<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").context("/proc/self/stat")?;
    // Fields after the command name (which may hold spaces) start with the state, field 3.
    let rest = stat.rsplit_once(')').context("stat format")?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| -> anyhow::Result<f64> { Ok(fields[i - 3].parse::<f64>()?) };
    Ok((ticks(14)? + ticks(15)?) / 100.0)
}

/// What the fit reads, read the way the pipeline reads it (as `benches/fit.rs`'s `read_only`).
fn read_only(files: &[PathBuf], options: &Options) -> anyhow::Result<u64> {
    let mut samples = 0;
    for path in files {
        let file = OpenRecording::open(path)?;
        if pipeline::calibration_metadata(file.metadata(), options) == Some(false) {
            continue;
        }
        file.for_each_activation(|activation| {
            samples += std::hint::black_box(activation).len() as u64;
            true
        })?;
    }
    Ok(samples)
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .context("usage: fit_vs_read <campaign folder> [rounds]")?;
    let rounds: usize = args.next().map_or(Ok(2), |r| r.parse())?;
    let files = pipeline::recording_files(Path::new(&dir))?;
    let options = Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: Vec::new(),
        held_out_repeats: false,
        evaluate: false,
        ..Options::default()
    };
    for _ in 0..rounds {
        let (wall, cpu) = (Instant::now(), cpu_seconds()?);
        let samples = read_only(&files, &options)?;
        let cpu = cpu_seconds()? - cpu;
        println!(
            "read_only {:.2} {cpu:.2} {samples}",
            wall.elapsed().as_secs_f64()
        );
        let (wall, cpu) = (Instant::now(), cpu_seconds()?);
        let outcome = pipeline::run(&files, &options, false, drift_recording::QUIET)?;
        let cpu = cpu_seconds()? - cpu;
        println!(
            "read_analyse_fit {:.2} {cpu:.2} {}",
            wall.elapsed().as_secs_f64(),
            outcome.samples_read
        );
    }
    Ok(())
}
