//! The `gyrodrift` subcommands, one per file.

use clap::{Parser, Subcommand};

mod campaign_args;
mod campaign_out;
pub mod check;
pub mod demo;
pub mod diagnose;
mod exit;
pub mod export;
pub mod export_image;
pub mod fit;
pub mod import;
pub mod import_campaign;
pub mod import_rosbag;
pub mod import_ulog;
mod in_sample;
pub mod interrupt;
mod log_terms;
mod measured;
mod progress;
mod reading;
pub mod report;
mod row_use;
mod shared_data;
mod sheet_logs;
pub mod simulate;

/// Exit status of every command: 0 done (for `check`: every limit met), 1 `check` found a unit ×
/// axis missing a limit (its report is written), 2 the command could not do its job (usage, input or
/// output error; the message says what and where), 130 interrupted (Ctrl-C; partial files removed).
pub const EXIT_CODES: &str = "Exit status: 0 done (check: every limit met); 1 check: a unit × axis misses a limit (report written); 2 usage, input or output error (the message says what and where); 130 interrupted by Ctrl-C (this run's partial files removed).";

/// The exit status for a command's outcome: see [`EXIT_CODES`].
pub fn exit_status(outcome: &anyhow::Result<()>) -> u8 {
    match outcome {
        Ok(()) => 0,
        Err(error) if error.downcast_ref::<exit::LimitsMissed>().is_some() => 1,
        Err(_) => 2,
    }
}

/// An error as one line: its chain of causes joined by `: `, leaving out a cause the text already
/// says (`thiserror` messages often embed their source: "x.mcap: invalid magic: invalid magic"
/// would repeat it), with digit runs longer than 16 shortened to scientific notation (a 301-digit
/// `1e300` is read as `1.000e300`).
pub fn message(error: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in error.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    shorten_numbers(&text)
}

/// Replaces every run of more than 16 digits (an integer part no f64 prints usefully) with
/// `d.ddde<exponent>`; the fraction after it, if any, is dropped.
fn shorten_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let start = i;
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
        let run = &chars[start..i];
        if run.len() > 16 {
            let mantissa: String = run[1..4].iter().collect();
            out.push_str(&format!("{}.{mantissa}e{}", run[0], run.len() - 1));
            // A fraction of a shortened number says nothing more.
            if i + 1 < chars.len() && chars[i] == '.' && chars[i + 1].is_ascii_digit() {
                i += 1;
                while i < chars.len() && chars[i].is_ascii_digit() {
                    i += 1;
                }
            }
        } else {
            out.extend(run);
        }
        if i < chars.len() && start == i {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

/// Temperature-drift correction for MEMS gyroscopes.
#[derive(Debug, Parser)]
#[command(name = "gyrodrift", version, about, after_help = EXIT_CODES)]
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
    /// Convert measured data (CSV, bench campaigns, PX4 ULog, ROS 2 bags) into recordings the
    /// other commands read.
    Import(import::Args),
    /// Write a recording in another format (ROS 2 bags with one message per sample).
    Export(export::Args),
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
        Command::Export(args) => export::run(&args),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_say_each_cause_once_and_shorten_long_numbers() {
        let io = std::io::Error::other("invalid magic");
        let error = anyhow::Error::new(io).context("x.mcap: invalid magic");
        assert_eq!(message(&error), "x.mcap: invalid magic");
        let error = anyhow::anyhow!("inner").context("outer");
        assert_eq!(message(&error), "outer: inner");
        let long = format!("got {}", 1e300);
        assert_eq!(shorten_numbers(&long), "got 1.000e300");
        assert_eq!(
            shorten_numbers("got -1e300 and 12.5"),
            "got -1e300 and 12.5"
        );
        assert_eq!(
            shorten_numbers(&format!("{} °/s", 123_456_789_012_345_678.9_f64)),
            "1.234e17 °/s"
        );
    }
}
