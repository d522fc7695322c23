//! `gyrodrift demo`: the built-in default job.

/// Options of `gyrodrift demo`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs the demo.
pub fn run(_args: &Args) -> anyhow::Result<()> {
    Ok(())
}
