//! `gyrodrift`: parse the command line and dispatch; the work lives in `gyrodrift::cli`.

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = gyrodrift::cli::Cli::parse();
    match gyrodrift::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
