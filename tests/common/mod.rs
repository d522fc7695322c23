//! Shared by the command-line tests: run the `gyrodrift` binary and keep what it printed.

use std::process::{Command, Output};

/// Runs `gyrodrift args`; its exit status and stdout + stderr as one text.
pub fn gyrodrift(args: &[&str]) -> (Output, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
        .args(args)
        .output()
        .unwrap();
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, text)
}

/// Runs `gyrodrift args`, which must succeed; what it printed.
#[allow(dead_code)] // not every test crate that includes this module calls it
pub fn ok(args: &[&str]) -> String {
    let (out, text) = gyrodrift(args);
    assert!(out.status.success(), "{args:?}: {text}");
    text
}
