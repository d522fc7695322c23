//! `gyrodrift simulate`: record a simulated calibration campaign as a folder of MCAP files.

use anyhow::{bail, Context};
use drift_sim::overrides::{parse_set_points, Overrides};
use drift_sim::size;
use drift_sim::Campaign;
use std::path::PathBuf;

/// Options of `gyrodrift simulate`. Flags override the campaign file; without a file the
/// paper's campaign is used (2 units; +30, +40, +33 °C; intervals 1…30 min; 3 repeats).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Campaign file (TOML, or JSON if it ends in `.json`).
    #[arg(long, short = 'c')]
    pub campaign: Option<PathBuf>,
    /// Output folder (recordings/, truth/, summary.json).
    #[arg(long, short = 'o', default_value = "out/campaign")]
    pub out: PathBuf,
    /// Seed of every random draw.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Number of units.
    #[arg(long)]
    pub units: Option<u32>,
    /// Chamber set points (°C): a list `30,40,33` or a range `-40:60:10` (from:to:step).
    #[arg(long, allow_hyphen_values = true)]
    pub set_points: Option<String>,
    /// Protocol off-times between activations (min), e.g. `1,2,5,10,15,20,30`.
    #[arg(long, value_delimiter = ',')]
    pub intervals: Option<Vec<f64>>,
    /// Recordings of each protocol series.
    #[arg(long)]
    pub repeats: Option<u32>,
    /// Also record field-like sessions (random off-times, ambient ramps, voltages, orientations).
    #[arg(long)]
    pub field: bool,
    /// Record only field-like sessions (no protocol).
    #[arg(long, conflicts_with = "field")]
    pub field_only: bool,
    /// Units without systematic drift (noise only): the evaluation's noise floor.
    #[arg(long)]
    pub zero_drift: bool,
    /// Units the paper's model represents exactly (bias linear in the sensor site's temperature,
    /// no element lag): a true null case for a diagnosis.
    #[arg(long, conflicts_with = "zero_drift")]
    pub paper_exact: bool,
    /// Hidden effects to switch on (default magnitudes): thermal_lag, acceleration,
    /// supply_voltage, cross_axis, rise_nonlinearity, ageing.
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Scale of every random component (0 = noise-free truth).
    #[arg(long)]
    pub noise_scale: Option<f64>,
    /// Store the true bias at 100 Hz instead of every sample (smaller, faster sidecar).
    #[arg(long)]
    pub truth_at_aux_rate: bool,
    /// Replace a campaign already in the output folder (its recordings/, truth/ and summary.json
    /// are removed first); without it, a non-empty output folder is refused.
    #[arg(long)]
    pub force: bool,
    /// Most the campaign may write, GB (estimated before anything is written).
    #[arg(long, default_value_t = size::DEFAULT_MAX_GB)]
    pub max_gb: f64,
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

/// The campaign these flags describe: the file's (or the built-in paper campaign) with the flags
/// applied as [`Overrides`].
pub fn campaign_from(args: &Args) -> anyhow::Result<Campaign> {
    let base = match &args.campaign {
        Some(path) => Campaign::from_file(path)?,
        None => Campaign::default(),
    };
    let set_points = match &args.set_points {
        Some(text) => {
            Some(parse_set_points(text).map_err(|e| anyhow::anyhow!("--set-points: {e}"))?)
        }
        None => None,
    };
    let overrides = Overrides {
        seed: args.seed,
        units: args.units,
        set_points,
        intervals: args.intervals.clone(),
        repeats: args.repeats,
        field: args.field,
        field_only: args.field_only,
        zero_drift: args.zero_drift,
        paper_exact: args.paper_exact,
        effects: args.effects.clone(),
        noise_scale: args.noise_scale,
        truth_at_aux_rate: args.truth_at_aux_rate,
    };
    Ok(overrides.apply(base)?)
}

/// Runs `gyrodrift simulate`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let campaign = campaign_from(args)?;
    if !(args.max_gb.is_finite() && args.max_gb > 0.0) {
        bail!("--max-gb must be > 0, got {}", args.max_gb);
    }
    let total = size::within(&campaign, args.max_gb, "--max-gb")?;
    let estimate_gb = size::estimate_bytes(&campaign, total) / 1e9;
    // Written into a staging folder put in place at the end: `--force` replaces an earlier
    // campaign only once the new one is whole, and a failed or interrupted run leaves it as it was.
    let staged =
        super::interrupt::stage(&args.out, args.force, &drift_sim::output_folder::SIMULATE)?;
    if !args.quiet {
        eprintln!(
            "simulating `{}`: {} samples, about {} → {}",
            campaign.name,
            total,
            size::gigabytes(estimate_gb),
            args.out.display()
        );
    }
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(total)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {percent:>3}% {msg} ({rate}, eta {eta})",
        )
        .context("progress bar template")?
        // Gyro samples per second, in millions: "1.5 M samples/s", not "1,538,355.8877/s".
        .with_key(
            "rate",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.1} M samples/s", state.per_sec() / 1e6);
            },
        ),
    );
    let summary = drift_sim::simulate_campaign(&campaign, staged.path(), |p| {
        bar.set_position(p.samples_done);
        bar.set_message(format!(
            "file {}/{}",
            (p.files_done + 1).min(p.files_total),
            p.files_total
        ));
    })
    .with_context(|| {
        format!(
            "simulating campaign `{}` into {}",
            campaign.name,
            args.out.display()
        )
    })?;
    bar.finish_and_clear();
    drift_sim::output_folder::summary_in_place(staged.path(), &args.out)?;
    staged.commit()?;
    let hours = summary.samples as f64 / f64::from(campaign.sample_rate_hz) / 3600.0;
    println!(
        "{} files, {} samples ({hours:.2} h at {} Hz), {:.1} MB recordings + {:.1} MB truth in {:.1} s → {}",
        summary.files.len(),
        summary.samples,
        campaign.sample_rate_hz,
        summary.recording_bytes as f64 / 1e6,
        summary.truth_bytes as f64 / 1e6,
        summary.wall_s,
        args.out.display()
    );
    Ok(())
}
