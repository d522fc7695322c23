//! `gyrodrift`: parse the command line and dispatch; the work lives in `gyrodrift::cli`.

use clap::Parser;

/// Stack of the thread the command runs on. Fitted tables are ~160 KiB values and a fit holds
/// several at once (more in unoptimised builds), so the work does not rely on the platform's main
/// thread stack (8 MiB on Linux, 1 MiB on Windows).
const STACK_BYTES: usize = 64 << 20;

fn main() -> std::process::ExitCode {
    let cli = gyrodrift::cli::Cli::parse();
    let worker = std::thread::Builder::new()
        .name("gyrodrift".into())
        .stack_size(STACK_BYTES)
        .spawn(move || gyrodrift::cli::run(cli));
    let outcome = match worker {
        Ok(handle) => handle
            .join()
            .unwrap_or_else(|_| Err(anyhow::anyhow!("internal error: the command panicked"))),
        Err(error) => Err(anyhow::anyhow!(
            "cannot start the command's thread: {error}"
        )),
    };
    match outcome {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
