//! `gyrodrift import campaign`: a bench campaign kept as one CSV file per activation plus an
//! activation sheet → a campaign folder that `fit`, `report`, `diagnose` and `check` read. An
//! activation file may also be a ROS 2 bag (an `.mcap` file or a bag folder) or a PX4 ULog
//! (`.ulg`), read as `import rosbag` and `import ulog` read one log.
//!
//! Everything is read and validated first (errors name the sheet or the activation file, the row
//! and the column); the recordings and `import.json` are then written into a temporary folder
//! beside the output, which is renamed to the output at the end: a failed import leaves nothing.

use std::path::PathBuf;

use drift_recording::read_sheet_campaign_with;

use super::reading::ReadingArgs;
use super::sheet_logs::LogArgs;

/// Options of `gyrodrift import campaign`.
#[derive(Debug, clap::Args)]
pub struct CampaignArgs {
    /// The activation sheet (CSV: `file`, `unit`, `set_point_celsius`, `series`, `repeat`,
    /// `activation`, `off_before_s`, `series_kind`, `switch_on_s`; optional `interval_min`,
    /// `switch_on_ambient_celsius`). Its `file` cells are relative to its folder.
    pub sheet: PathBuf,
    /// Output: a campaign folder (`recordings/<unit>_sp<set point>C_<kind>.mcap`,
    /// `import.json`); it must not exist or be empty, or hold an earlier import and `--force`.
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Replace an earlier import in the output folder, whole.
    #[arg(long)]
    pub force: bool,
    /// Column mapping, units and timing of every activation file.
    #[command(flatten)]
    pub reading: ReadingArgs,
    /// Topics and clock of the activation files that are ROS 2 bags or ULog files.
    #[command(flatten)]
    pub logs: LogArgs,
}

/// Runs `gyrodrift import campaign`.
pub fn run(args: &CampaignArgs) -> anyhow::Result<()> {
    let options = args.reading.options()?;
    super::campaign_out::refuse_existing(&args.out, args.force)?;
    let clock = args.logs.clock()?;
    let max_gap = args.reading.max_gap;
    let recordings = read_sheet_campaign_with(&args.sheet, &options, &|path, csv| {
        args.logs
            .read(path, csv, clock, max_gap)
            .map(|read| read.map_err(|e| format!("{e:#}").into()))
    })?;
    let manifest = serde_json::json!({
        "sheet": args.sheet.display().to_string(),
        "sample_rate_hz": args.reading.rate_hz,
        "timing": args.reading.timing,
    });
    let mut lines =
        super::campaign_out::write_campaign(&args.out, args.force, &recordings, &manifest)?;
    lines.push(format!(
        "{}: {} recordings → {}",
        args.sheet.display(),
        recordings.len(),
        args.out.display()
    ));
    for line in lines {
        println!("{line}");
    }
    Ok(())
}
