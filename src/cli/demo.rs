//! `gyrodrift demo`: the built-in default job.
//!
//! Until the simulator and the fitter land, the demo exercises what exists: the firmware-side
//! corrector. It loads the demonstration models shipped with the shared test vectors (synthetic
//! tables, not fitted from data), runs every vector case through the host corrector, checks the
//! outputs against the vectors bit for bit, and writes the firmware table images.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{bail, Context};
use drift_core::blob::{encode, Image};
use drift_core::{Corrector, Flags, Model, ModifiedTables, PolynomialTables, Sample};
use serde_json::Value;

use crate::output::write_atomic;

/// The shared test vectors, compiled in so the demo runs anywhere.
const VECTORS: &str = include_str!("../../testdata/vectors.json");

/// Options of `gyrodrift demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder for the firmware table images (created if missing).
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
}

/// What one case produced.
struct CaseSummary {
    samples: usize,
    mismatches: usize,
    bias_range: (f32, f32),
    flags: Flags,
}

fn bits(value: &Value) -> anyhow::Result<u32> {
    value
        .as_u64()
        .and_then(|v| u32::try_from(v).ok())
        .context("expected a 32-bit integer")
}

fn run_case<M: Model>(model: &M, case: &Value) -> anyhow::Result<CaseSummary> {
    let mut corrector = Corrector::new(model)?;
    if let Some(raw) = case["switch_on_raw"].as_array() {
        let raw: Vec<f32> = raw
            .iter()
            .map(|v| bits(v).map(f32::from_bits))
            .collect::<Result<_, _>>()?;
        let raw: [f32; 3] = raw
            .try_into()
            .map_err(|_| anyhow::anyhow!("switch_on_raw needs 3 values"))?;
        // Cases marked `power_on_fails` expect this error; the samples then pass through, flagged.
        let _ = corrector.power_on(raw);
    }
    let samples = case["samples"].as_array().context("samples")?;
    let expected = case["expected"].as_array().context("expected")?;
    let mut summary = CaseSummary {
        samples: samples.len(),
        mismatches: 0,
        bias_range: (f32::INFINITY, f32::NEG_INFINITY),
        flags: Flags::NONE,
    };
    for (input, want) in samples.iter().zip(expected) {
        let input: Vec<u32> = input
            .as_array()
            .context("sample")?
            .iter()
            .map(bits)
            .collect::<Result<_, _>>()?;
        let want: Vec<u32> = want
            .as_array()
            .context("expected")?
            .iter()
            .map(bits)
            .collect::<Result<_, _>>()?;
        let [ms, rx, ry, rz, tx, ty, tz] = input[..] else {
            bail!("a sample has 7 values")
        };
        let out = corrector.correct(&Sample {
            since_power_on_ms: ms,
            rate_dps: [rx, ry, rz].map(f32::from_bits),
            temperature_raw: [tx, ty, tz].map(f32::from_bits),
        });
        let got = out
            .corrected_dps
            .iter()
            .chain(&out.bias_dps)
            .map(|v| v.to_bits())
            .chain(out.flags.iter().map(|f| u32::from(f.0)));
        for (g, &w) in got.zip(&want) {
            let both_nan = f32::from_bits(g).is_nan() && f32::from_bits(w).is_nan();
            if g != w && !both_nan {
                summary.mismatches += 1;
            }
        }
        for (bias, flags) in out.bias_dps.iter().zip(out.flags) {
            summary.bias_range.0 = summary.bias_range.0.min(*bias);
            summary.bias_range.1 = summary.bias_range.1.max(*bias);
            summary.flags |= flags;
        }
    }
    Ok(summary)
}

fn flag_names(flags: Flags) -> String {
    let names = [
        (Flags::AMBIENT_OUT_OF_RANGE, "ambient"),
        (Flags::RISE_OUT_OF_SPAN, "rise"),
        (Flags::PAST_LAST_REFERENCE, "past-last"),
        (Flags::TEMPERATURE_OUT_OF_RANGE, "temp-range"),
        (Flags::TEMPERATURE_INVALID, "temp-invalid"),
        (Flags::TEMPERATURE_STUCK, "temp-stuck"),
        (Flags::RATE_INVALID, "rate-invalid"),
        (Flags::NOT_POWERED_ON, "not-powered"),
        (Flags::MODEL_INVALID, "model-invalid"),
    ];
    let seen: Vec<&str> = names
        .iter()
        .filter(|(f, _)| flags.contains(*f))
        .map(|(_, n)| *n)
        .collect();
    if seen.is_empty() {
        "-".into()
    } else {
        seen.join(",")
    }
}

fn image<M: Image>(model: &M) -> anyhow::Result<Vec<u8>> {
    let mut buffer = vec![0; 1 << 20];
    let len = encode(model, &mut buffer).map_err(|e| anyhow::anyhow!("{e}"))?;
    buffer.truncate(len);
    Ok(buffer)
}

/// Runs the demo.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let file: Value = serde_json::from_str(VECTORS).context("parsing the built-in test vectors")?;
    let mut modified: BTreeMap<String, ModifiedTables> = BTreeMap::new();
    let mut polynomial: BTreeMap<String, PolynomialTables> = BTreeMap::new();
    println!("gyrodrift demo — the firmware-side corrector on the built-in demonstration models");
    println!("(synthetic tables shipped with testdata/vectors.json; simulate → fit → report arrives with issues 3–4)\n");
    for named in file["models"].as_array().context("models")? {
        let name = named["name"].as_str().context("model name")?.to_owned();
        let bytes = match named["kind"].as_str() {
            Some("modified") => {
                let tables: ModifiedTables = serde_json::from_value(named["tables"].clone())?;
                let bytes = image(&tables)?;
                modified.insert(name.clone(), tables);
                bytes
            }
            Some("polynomial") => {
                let tables: PolynomialTables = serde_json::from_value(named["tables"].clone())?;
                let bytes = image(&tables)?;
                polynomial.insert(name.clone(), tables);
                bytes
            }
            other => bail!("model {name}: unknown kind {other:?}"),
        };
        let path = args.out.join(format!("{name}.bin"));
        write_atomic(&path, &bytes)?;
        println!(
            "model {name:<12} firmware image {:>6} bytes → {}",
            bytes.len(),
            path.display()
        );
    }
    println!(
        "\n{:<34} {:<12} {:>7}  {:>21}  flags seen",
        "case", "model", "samples", "bias range °/s"
    );
    let (mut total, mut mismatches) = (0, 0);
    for case in file["cases"].as_array().context("cases")? {
        let name = case["name"].as_str().context("case name")?;
        let model = case["model"].as_str().context("case model")?;
        let summary = match (modified.get(model), polynomial.get(model)) {
            (Some(m), _) => run_case(m, case)?,
            (_, Some(p)) => run_case(p, case)?,
            _ => bail!("case {name}: unknown model {model}"),
        };
        total += summary.samples;
        mismatches += summary.mismatches;
        let (lo, hi) = summary.bias_range;
        println!(
            "{name:<34} {model:<12} {:>7}  {lo:>+9.5} … {hi:>+9.5}  {}",
            summary.samples,
            flag_names(summary.flags)
        );
    }
    println!(
        "\n{total} samples corrected; outputs differing from the shared vectors: {mismatches}"
    );
    if mismatches > 0 {
        bail!("{mismatches} outputs differ from testdata/vectors.json");
    }
    Ok(())
}
