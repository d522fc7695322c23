//! `gyrodrift simulate`: record a simulated calibration campaign as a folder of MCAP files.

use anyhow::Context;
use drift_sim::campaign::set_point_range;
use drift_sim::{Campaign, Field, UnitModel};
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
    /// No progress bar.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

fn parse_set_points(text: &str) -> anyhow::Result<Vec<f64>> {
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .with_context(|| format!("--set-points: `{s}` is not a number"))
    };
    if text.contains(':') {
        let parts: Vec<&str> = text.split(':').collect();
        anyhow::ensure!(
            parts.len() == 3,
            "--set-points range must be from:to:step, got `{text}`"
        );
        let points = set_point_range(number(parts[0])?, number(parts[1])?, number(parts[2])?);
        anyhow::ensure!(!points.is_empty(), "--set-points range `{text}` is empty");
        return Ok(points);
    }
    text.split(',').map(number).collect()
}

/// Builds the campaign from the file (if any) and the flags.
pub fn campaign_from(args: &Args) -> anyhow::Result<Campaign> {
    let mut c = match &args.campaign {
        Some(path) => Campaign::from_file(path)?,
        None => Campaign::default(),
    };
    if let Some(seed) = args.seed {
        c.seed = seed;
    }
    if let Some(units) = args.units {
        c.units = units;
    }
    if let Some(text) = &args.set_points {
        c.set_points_celsius = parse_set_points(text)?;
    }
    if args.intervals.is_some() || args.repeats.is_some() {
        let p = c.protocol.get_or_insert_with(Default::default);
        if let Some(intervals) = &args.intervals {
            p.intervals_min.clone_from(intervals);
        }
        if let Some(repeats) = args.repeats {
            p.repeats = repeats;
        }
    }
    if args.field || args.field_only {
        c.field.get_or_insert_with(Field::default);
    }
    if args.field_only {
        c.protocol = None;
    }
    if args.zero_drift {
        c.unit_model = UnitModel::ZeroSystematicDrift;
    }
    if args.paper_exact {
        c.unit_model = UnitModel::PaperExact;
    }
    for name in &args.effects {
        c.effects.enable(name.trim()).map_err(anyhow::Error::msg)?;
    }
    if args.truth_at_aux_rate {
        c.truth_bias = drift_sim::campaign::TruthBias::AuxRate;
    }
    if let Some(scale) = args.noise_scale {
        c.noise_scale = scale;
    }
    c.validate()?;
    Ok(c)
}

/// Runs `gyrodrift simulate`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let campaign = campaign_from(args)?;
    let total = drift_sim::simulate::total_samples(&campaign);
    let bar = if args.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(total)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {percent:>3}% {msg} ({per_sec}, eta {eta})",
        )
        .context("progress bar template")?,
    );
    let summary = drift_sim::simulate_campaign(&campaign, &args.out, |p| {
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
