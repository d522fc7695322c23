//! `gyrodrift fit`: recordings → the paper's tables and the baselines, as JSON and firmware images.

use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_core::blob::{encode, Image};
use drift_fit::{FitSettings, FittedUnit};

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use crate::output::write_atomic;
use drift_fit::pipeline;

/// Options of `gyrodrift fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Recordings and fit settings.
    #[command(flatten)]
    pub input: CampaignArgs,
    /// Output folder: one subfolder per unit.
    #[arg(long, short = 'o', default_value = "out/tables")]
    pub out: PathBuf,
}

/// Reads fit settings from a JSON file, or the defaults.
pub fn load_settings(path: Option<&Path>) -> anyhow::Result<FitSettings> {
    match path {
        None => Ok(FitSettings::default()),
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            serde_json::from_str(&text)
                .with_context(|| format!("{}: not valid fit settings", path.display()))
        }
    }
}

fn image<M: Image>(model: &M) -> anyhow::Result<Vec<u8>> {
    let mut buffer = vec![0; 1 << 20];
    let len = encode(model, &mut buffer).map_err(|e| anyhow::anyhow!("{e}"))?;
    buffer.truncate(len);
    Ok(buffer)
}

/// Writes each unit's models as `<out>/<unit>/{modified,by_history,standard,third_order}.{json,bin}`.
///
/// Every file is encoded in memory first, so an encoding error leaves the folder untouched; each
/// file is then replaced atomically (`write_atomic`), so none is ever half-written.
pub fn write_tables(out: &Path, fitted: &[FittedUnit]) -> anyhow::Result<()> {
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for unit in fitted {
        let dir = out.join(&unit.unit_id);
        files.push((
            dir.join("modified.json"),
            serde_json::to_string_pretty(&unit.modified)?.into_bytes(),
        ));
        files.push((dir.join("modified.bin"), image(&unit.modified)?));
        // The same curves with stage 3 keyed by heating history (firmware that keeps what it knew
        // of the previous activation: `power_on_after`).
        files.push((
            dir.join("by_history.json"),
            serde_json::to_string_pretty(&unit.by_history)?.into_bytes(),
        ));
        files.push((dir.join("by_history.bin"), image(&unit.by_history)?));
        for (name, model) in [
            ("standard", &unit.standard),
            ("third_order", &unit.third_order),
        ] {
            files.push((
                dir.join(format!("{name}.json")),
                serde_json::to_string_pretty(model)?.into_bytes(),
            ));
            files.push((dir.join(format!("{name}.bin")), image(model)?));
        }
    }
    for (path, bytes) in &files {
        write_atomic(path, bytes)?;
    }
    Ok(())
}

/// Runs `gyrodrift fit`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let files = pipeline::recording_files(&args.input.campaign)?;
    let options = args.input.options(&[], false)?;
    let steps = Steps::new(args.input.quiet);
    let outcome = pipeline::run(&files, &options, false, &|s, d, t| steps.update(s, d, t))
        .map_err(|e| super::measured::explain(e, &files))?;
    steps.finish();
    write_tables(&args.out, &outcome.fitted)?;
    let seconds = |step: &str| {
        outcome
            .timings
            .iter()
            .find(|(s, _)| s.starts_with(step))
            .map_or(0.0, |(_, t)| *t)
    };
    let (read, analyse, fit) = (
        seconds("read recordings"),
        seconds("analyse"),
        seconds("fit tables"),
    );
    println!(
        "{} samples read in {read:.2} s; analysis {analyse:.2} s + fit {fit:.2} s = {:.2}× the reading time",
        outcome.samples_read,
        (analyse + fit) / read.max(1e-9)
    );
    for unit in &outcome.fitted {
        let refs: Vec<String> = unit.modified.axes[0]
            .reference_ms
            .iter()
            .map(|ms| format!("{}", f64::from(*ms) / 1000.0))
            .collect();
        println!(
            "{}: {} curves × {} ambients, reference times (X) {} s → {}",
            unit.unit_id,
            unit.curve_keys.len(),
            unit.modified.axes[0].ambients.len(),
            refs.join(", "),
            args.out.join(&unit.unit_id).display()
        );
        // What the fit decided or found that a reader must know (dropped curves, stage 3's premise).
        for note in &unit.notes {
            println!("  note: {note}");
        }
    }
    Ok(())
}
