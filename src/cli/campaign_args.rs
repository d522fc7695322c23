//! The arguments every fitting command shares: which recordings, which set points to fit, which
//! fit settings, and whether to show progress.

use std::path::{Path, PathBuf};

use anyhow::Context;

use drift_evaluate::pipeline::Options;
use drift_fit::FitSettings;
use drift_recording::paper;

/// Recordings and fit settings.
#[derive(Debug, clap::Args)]
pub struct CampaignArgs {
    /// Campaign folder (with `recordings/`) or a folder of `.mcap` recordings.
    #[arg(required_unless_present = "calibration_data")]
    pub campaign: Option<PathBuf>,
    /// The recordings to fit on, instead of the positional campaign (with `--evaluation-data` of
    /// `report` or `diagnose`: judged on another source).
    #[arg(long, value_name = "DIR", conflicts_with = "campaign")]
    pub calibration_data: Option<PathBuf>,
    /// Chamber set points to fit, °C (protocol activations only).
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = paper::CALIBRATION_SET_POINTS_CELSIUS,
        allow_hyphen_values = true
    )]
    pub calibration: Vec<f64>,
    /// Fit settings as JSON (fields of `drift_fit::FitSettings`; missing fields keep defaults,
    /// unknown ones are an error).
    #[arg(long)]
    pub settings: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short = 'q')]
    pub quiet: bool,
}

impl CampaignArgs {
    /// The recordings fitted on: the campaign, or `--calibration-data`.
    pub fn source(&self) -> &Path {
        self.campaign
            .as_deref()
            .or(self.calibration_data.as_deref())
            .unwrap_or(Path::new("."))
    }

    /// Pipeline options: fit on the calibration set points, validate on `validation`.
    pub fn options(&self, validation: &[f64], evaluate: bool) -> anyhow::Result<Options> {
        Ok(Options {
            calibration_set_points: self.calibration.clone(),
            validation_set_points: validation.to_vec(),
            fit: load_settings(self.settings.as_deref())?,
            held_out_repeats: evaluate,
            evaluate,
            switch_on_ambient: None,
        })
    }
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
