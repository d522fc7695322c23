//! The `gyrodrift` subcommands, one per file.

use clap::{Parser, Subcommand};

mod campaign_args;
pub mod check;
pub mod demo;
pub mod diagnose;
mod extend;
pub mod fit;
pub mod import;
mod import_campaign;
mod import_ulog;
mod measured;
mod progress;
pub mod report;
pub mod simulate;

/// Temperature-drift correction for MEMS gyroscopes.
#[derive(Debug, Parser)]
#[command(name = "gyrodrift", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the built-in demonstration (the README's main job).
    Demo(demo::Args),
    /// Simulate a calibration campaign and record it as MCAP files.
    Simulate(simulate::Args),
    /// Fit the paper's tables and the baselines from recordings.
    Fit(fit::Args),
    /// Fit, evaluate on data the fit did not see, and write the report.
    Report(report::Args),
    /// Check a unit's stored tables on new recordings: is the calibration still valid?
    Check(check::Args),
    /// Rank what explains the residual the paper's model leaves.
    Diagnose(diagnose::Args),
    /// Convert measured data (CSV) into a recording the other commands read.
    Import(import::Args),
}

/// Runs one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(args) => demo::run(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Diagnose(args) => diagnose::run(&args),
        Command::Import(args) => import::run(&args),
    }
}
