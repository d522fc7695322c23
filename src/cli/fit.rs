//! `gyrodrift fit`: recordings → the paper's tables and the baselines, as JSON and firmware images.

use std::path::PathBuf;

use super::campaign_args::CampaignArgs;
use super::progress::Steps;
use drift_evaluate::pipeline;
use drift_recording::output_folder::{Owned, Writer};

/// Options of `gyrodrift fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Recordings and fit settings.
    #[command(flatten)]
    pub input: CampaignArgs,
    /// Output folder: one subfolder per unit.
    #[arg(long, short = 'o', default_value = "out/tables")]
    pub out: PathBuf,
    /// Replace an earlier `gyrodrift fit` output in the output folder, whole.
    #[arg(long)]
    pub force: bool,
}

/// `fit` as a writer of output folders.
pub const WRITER: Writer = Writer {
    command: "fit",
    product: "tables folder",
    doing: "fitting",
    owned: Owned::Marker,
};

/// Runs `gyrodrift fit`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let files = pipeline::recording_files(args.input.source())?;
    let options = args.input.options(&[], false)?;
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let steps = Steps::new(args.input.quiet);
    let outcome = pipeline::run(&files, &options, false, &steps)
        .map_err(|e| super::measured::explain(e, &files))?;
    steps.finish();
    drift_evaluate::tables_folder::write(staged.path(), &outcome.fitted)?;
    super::in_sample::write(staged.path(), &files, &options)?;
    staged.commit()?;
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
