//! Pure-Rust correction throughput, the reference for the Python binding's benchmark
//! (`crates/drift-py/bench/bench_correct.py` runs this and compares).
//!
//! Corrects the same deterministic synthetic stream the Python script builds (integer formulas,
//! exact in f32 on both sides) with the demonstration models of `testdata/vectors.json`, from
//! memory to memory, and prints one line per model:
//!
//! ```text
//! <model> <samples> <best seconds> <samples per second> <samples per second, fresh outputs> <checksum>
//! ```
//!
//! The main figure writes into an output buffer allocated (and touched) once; the "fresh outputs"
//! figure allocates a new buffer in every run, as a call that returns new arrays must, and so also
//! pays the kernel's first-touch page faults.
//!
//! The checksum (XOR of every output's bits) lets the Python side check that it computed the same
//! thing. Usage: `cargo run --release --example correct_throughput -- [samples] [repeats] [model|all]
//! [stuck_after]`. The test vectors' models count 20 identical temperature readings as a stuck sensor
//! (so the vectors exercise that path), which holds about 60 % of this stream's samples; a
//! `stuck_after` of 2000 (drift-core's default) measures the typical case, where none is stuck.

use std::time::Instant;

use anyhow::{bail, Context};
use drift_core::blob::{decode, Image};
use drift_core::{Corrector, Model, ModifiedTables, Output, PolynomialTables, Sample};

const VECTORS: &str = include_str!("../testdata/vectors.json");

/// Sample `i` of the synthetic stream (mirrored in `bench_correct.py`'s `stream`).
fn sample(i: u32) -> Sample {
    let axis = |a: u32| {
        let rate = ((i.wrapping_mul(7).wrapping_add(a * 13)) % 2001) as f32 - 1000.0;
        let temperature = 6600.0 + ((i / (50 + 10 * a)) % 800) as f32;
        (rate * 0.001, temperature)
    };
    let [(rx, tx), (ry, ty), (rz, tz)] = [axis(0), axis(1), axis(2)];
    Sample {
        since_power_on_ms: i % 150_000,
        rate_dps: [rx, ry, rz],
        temperature_raw: [tx, ty, tz],
    }
}

fn model<M: Image>(vectors: &serde_json::Value, name: &str) -> anyhow::Result<M> {
    let models = vectors["models"].as_array().context("models")?;
    let named = models
        .iter()
        .find(|m| m["name"] == name)
        .with_context(|| format!("model {name}"))?;
    let hex = named["image_hex"].as_str().context("image_hex")?;
    let bytes = (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(hex.get(i..i + 2).unwrap_or("zz"), 16))
        .collect::<Result<Vec<u8>, _>>()?;
    decode(&bytes).map_err(|e| anyhow::anyhow!("{name}: {e}"))
}

/// Best-of-`repeats` seconds to correct `samples` into `outputs` (allocated once) and into a
/// freshly allocated buffer, and the outputs' checksum.
fn run<M: Model>(
    model: &M,
    samples: &[Sample],
    outputs: &mut [Output],
    repeats: u32,
) -> anyhow::Result<(f64, f64, u32)> {
    let switch_on = samples.first().context("no samples")?.temperature_raw;
    let mut best = f64::INFINITY;
    let mut best_fresh = f64::INFINITY;
    for _ in 0..repeats {
        let mut corrector = Corrector::new(model)?;
        corrector.power_on(switch_on)?;
        let start = Instant::now();
        corrector.correct_block(samples, outputs);
        best = best.min(start.elapsed().as_secs_f64());

        let mut corrector = Corrector::new(model)?;
        corrector.power_on(switch_on)?;
        let start = Instant::now();
        let mut fresh = Vec::with_capacity(samples.len());
        fresh.extend(samples.iter().map(|sample| corrector.correct(sample)));
        best_fresh = best_fresh.min(start.elapsed().as_secs_f64());
        if fresh != outputs {
            bail!("fresh and reused outputs differ");
        }
    }
    let checksum = outputs.iter().fold(0_u32, |acc, o| {
        let floats = o
            .corrected_dps
            .iter()
            .chain(&o.bias_dps)
            .map(|v| v.to_bits());
        let flags = o.flags.iter().map(|f| u32::from(f.0));
        floats.chain(flags).fold(acc, |a, b| a ^ b)
    });
    Ok((best, best_fresh, checksum))
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let count: u32 = args.first().map_or(Ok(10_000_000), |s| s.parse())?;
    let repeats: u32 = args.get(1).map_or(Ok(3), |s| s.parse())?;
    if count == 0 || repeats == 0 {
        bail!("samples and repeats must be positive");
    }
    let vectors: serde_json::Value = serde_json::from_str(VECTORS)?;
    let samples: Vec<Sample> = (0..count).map(sample).collect();
    let mut outputs = vec![Output::default(); samples.len()];
    let mut modified: ModifiedTables = model(&vectors, "modified")?;
    let mut standard: PolynomialTables = model(&vectors, "standard")?;
    let mut third_order: PolynomialTables = model(&vectors, "third_order")?;
    if let Some(stuck_after) = args.get(3) {
        let stuck_after: u16 = stuck_after.parse().context("stuck_after (0..=65535)")?;
        for settings in [
            &mut modified.settings,
            &mut standard.settings,
            &mut third_order.settings,
        ] {
            settings.stuck_after_samples = stuck_after;
        }
    }
    // An optional third argument keeps one model (for a profile of one model's block path).
    let only = args
        .get(2)
        .map(String::as_str)
        .filter(|only| *only != "all");
    let wanted = |name: &str| only.is_none_or(|only| only == name);
    for name in ["modified", "standard", "third_order"] {
        if !wanted(name) {
            continue;
        }
        let (seconds, fresh_seconds, checksum) = match name {
            "modified" => run(&modified, &samples, &mut outputs, repeats)?,
            "standard" => run(&standard, &samples, &mut outputs, repeats)?,
            _ => run(&third_order, &samples, &mut outputs, repeats)?,
        };
        println!(
            "{name} {count} {seconds:.6} {:.0} {:.0} {checksum:08x}",
            f64::from(count) / seconds,
            f64::from(count) / fresh_seconds
        );
    }
    Ok(())
}
