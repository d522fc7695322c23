//! `gyrodrift demo`: the main job on its built-in default. Simulates the paper's campaign (2 units;
//! +30 and +40 °C for calibration, +33 °C for validation; intervals 1–30 min; 3 repeats) with
//! field-like sessions beside it, and a zero-drift unit for the noise floor; fits the tables on
//! +30/+40 °C; evaluates on everything the fit did not see; writes the tables and the report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use drift_sim::campaign::TruthBias;
use drift_sim::{Campaign, Field, Protocol, UnitModel};

use super::progress::Steps;
use super::report::{headline, make};
use drift_evaluate::pipeline::{Options, Outcome};
use drift_recording::output_folder::{Owned, Writer};

/// Options of `gyrodrift demo`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output folder: `campaign/`, `noise-floor/`, `report/` (with `tables/`).
    #[arg(long, short = 'o', default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed of the simulated campaign.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// No progress bars.
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Replace an earlier `gyrodrift demo` output in the output folder, whole.
    #[arg(long)]
    pub force: bool,
}

/// What a demo writes into its output folder.
const WRITTEN: [&str; 3] = ["campaign", "noise-floor", "report"];

/// `demo` as a writer of output folders; a demo's folder without the marker is an older demo's.
pub const WRITER: Writer = Writer {
    command: "demo",
    product: "demo",
    doing: "writing the demo",
    owned: Owned::MarkerOrNames(&WRITTEN),
};

/// The demo's campaigns: the paper's, with field sessions; and a small zero-drift one.
pub fn campaigns(seed: u64) -> (Campaign, Campaign) {
    let paper = Campaign {
        seed,
        field: Some(Field::default()),
        // The true bias at 100 Hz is exact to ~1e-8 °/s and keeps the sidecar 3× smaller.
        truth_bias: TruthBias::AuxRate,
        ..Campaign::default()
    };
    let noise = Campaign {
        name: "noise-floor".into(),
        seed: seed.wrapping_add(1000),
        units: 1,
        unit_model: UnitModel::ZeroSystematicDrift,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 30.0],
            repeats: 2,
            ..Protocol::default()
        }),
        truth_bias: TruthBias::AuxRate,
        ..Campaign::default()
    };
    (paper, noise)
}

/// Runs the demo.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    // Everything is written into a staging folder and put in place at the end: an interrupted or
    // failed demo leaves an earlier demo's campaigns and report as they were.
    let staged = super::interrupt::stage(&args.out, args.force, &WRITER)?;
    let (paper, noise) = campaigns(args.seed);
    let bytes: f64 = [&paper, &noise]
        .iter()
        .map(|c| drift_sim::size::estimate_bytes(c, drift_sim::simulate::total_samples(c)))
        .sum();
    if !args.quiet {
        // Disk use, stated before the large writes start.
        eprintln!(
            "demo: simulating two campaigns, about {} of recordings and truth → {}",
            drift_sim::size::gigabytes(bytes / 1e9),
            args.out.display()
        );
    }
    let steps = Steps::new(args.quiet);
    let mut simulated = Vec::new();
    for (campaign, folder) in [(&paper, "campaign"), (&noise, "noise-floor")] {
        let dir = staged.path().join(folder);
        let step = format!("simulating `{}`", campaign.name);
        let total = drift_sim::simulate::total_samples(campaign);
        let summary = drift_sim::simulate_campaign(campaign, &dir, |p| {
            steps.update(&step, p.samples_done, total)
        })
        .with_context(|| format!("simulating into {}", dir.display()))?;
        simulated.push((campaign.name.clone(), args.out.join(folder), summary));
    }
    steps.finish();
    let options = Options::default();
    let mut provenance = vec![format!(
        "Made by `gyrodrift demo --seed {}`: simulated campaigns (drift-sim), fit on +30/+40 °C protocol activations, evaluated with drift-core's f32 corrector (the firmware's code) on data the fit did not see.",
        args.seed
    )];
    for (name, dir, summary) in &simulated {
        provenance.push(format!(
            "- `{name}`: {} samples ({:.1} h at 1000 Hz) in {:.1} s → `{}`",
            summary.samples,
            summary.samples as f64 / 3.6e6,
            summary.wall_s,
            dir.display()
        ));
    }
    let (_, outcome) = make(
        &staged.path().join("campaign"),
        Some(&staged.path().join("noise-floor")),
        &options,
        &staged.path().join("report"),
        provenance,
        args.quiet,
    )?;
    staged.commit()?;
    print!(
        "{}",
        console(
            &outcome,
            &options,
            &args.out.join("report"),
            started.elapsed().as_secs_f64()
        )
    );
    Ok(())
}

/// What the demo prints once its report is in `report_dir`: the report's headline (the drift
/// table, the absolute-error verdict, the field-like results), then where the tables and the
/// report are and how long it all took.
pub fn console(outcome: &Outcome, options: &Options, report_dir: &Path, total_s: f64) -> String {
    format!(
        "\n{}tables:  {}\nreport:  {}\ntotal:   {total_s:.1} s\n",
        headline(outcome, options),
        report_dir.join("tables").display(),
        report_dir.join("report.md").display(),
    )
}
