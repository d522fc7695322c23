//! `gyrodrift`: parse the command line and dispatch; the work lives in `gyrodrift::cli`.

use clap::Parser;

/// Stack of the thread the command runs on. Fitted tables are ~160 KiB values and a fit holds
/// several at once (more in unoptimised builds), so the work does not rely on the platform's main
/// thread stack (8 MiB on Linux, 1 MiB on Windows).
const STACK_BYTES: usize = 64 << 20;

/// Whether a panic is `println!` finding stdout closed (`gyrodrift … | head`): std's message for
/// EPIPE. Not a bug to report, and the default hook's backtrace advice would say it is one.
fn broken_pipe(payload: &(dyn std::any::Any + Send)) -> bool {
    let message = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied());
    message.is_some_and(|m| m.contains("Broken pipe"))
}

fn main() -> std::process::ExitCode {
    let cli = gyrodrift::cli::Cli::parse();
    gyrodrift::cli::interrupt::install();
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !broken_pipe(info.payload()) {
            report(info);
        }
    }));
    let worker = std::thread::Builder::new()
        .name("gyrodrift".into())
        .stack_size(STACK_BYTES)
        .spawn(move || gyrodrift::cli::run(cli));
    let outcome = match worker {
        Ok(handle) => handle.join().unwrap_or_else(|panic| {
            Err(if broken_pipe(&*panic) {
                // Files are written whole or not at all; what was not yet written is not.
                anyhow::anyhow!("standard output was closed (broken pipe); the command stopped")
            } else {
                anyhow::anyhow!("internal error: the command panicked")
            })
        }),
        Err(error) => Err(anyhow::anyhow!(
            "cannot start the command's thread: {error}"
        )),
    };
    if let Err(error) = &outcome {
        eprintln!("error: {}", gyrodrift::cli::message(error));
    }
    std::process::ExitCode::from(gyrodrift::cli::exit_status(&outcome))
}
