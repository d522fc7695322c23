#!/usr/bin/env bash
# The one test command (README): installs what it needs, then runs every check in order.
# Idempotent; safe to re-run. Exits non-zero at the first failing check.
set -euo pipefail
cd "$(dirname "$0")/.."

# Each step prints the time since the start, so a slow step shows where the budget goes.
step() { printf '\n=== [%dm%02ds] %s\n' $((SECONDS / 60)) $((SECONDS % 60)) "$*"; }
trap 'printf "\n=== [%dm%02ds] end (exit %d)\n" $((SECONDS / 60)) $((SECONDS % 60)) $?' EXIT

step "toolchain: Rust stable with rustfmt, clippy, llvm-tools and the Cortex-M4F target"
rustup show active-toolchain >/dev/null
rustup component add rustfmt clippy llvm-tools >/dev/null 2>&1 || true
rustup target add thumbv7em-none-eabihf >/dev/null

step "system packages: qemu-system-arm (emulated Cortex-M4), arm-none-eabi-gcc and newlib (the C example)"
if ! command -v qemu-system-arm >/dev/null || ! command -v arm-none-eabi-gcc >/dev/null \
    || [ ! -e /usr/lib/arm-none-eabi/newlib/thumb/v7e-m+fp/hard/librdimon_nano.a ]; then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq qemu-system-arm \
        gcc-arm-none-eabi libnewlib-arm-none-eabi >/dev/null
fi
qemu-system-arm --version | head -n 1
arm-none-eabi-gcc --version | head -n 1

step "format"
cargo fmt --all --check
(cd embedded && cargo fmt --all --check)

step "structure: no two modules of a crate import each other"
python3 scripts/module-cycles.py

step "clippy: host workspace, all targets and features"
cargo clippy --workspace --all-targets --all-features --locked -- -D warnings

step "clippy: drift-core for thumbv7em-none-eabihf, each feature set, and its C interface (no_std there)"
cargo clippy -p drift-core --target thumbv7em-none-eabihf --locked -- -D warnings
cargo clippy -p drift-core --target thumbv7em-none-eabihf --no-default-features --locked -- -D warnings
cargo clippy -p drift-core-ffi --target thumbv7em-none-eabihf --locked -- -D warnings

step "build: drift-core for thumbv7em-none-eabihf (release, no_std, no heap)"
cargo build -p drift-core --target thumbv7em-none-eabihf --release --locked

step "tests: workspace (all features) and drift-core without default features"
cargo test --workspace --all-features --locked
cargo test -p drift-core --no-default-features --locked  # the vectors and image tests need serde (required-features)

step "fuzz targets: format and compile on stable (the corpora are replayed by the tests above)"
# Fuzzing itself (nightly, minutes per target) is scripts/fuzz.sh; Miri over drift-core takes
# far longer than this script's budget: both are run by hand (docs/reliability.md).
(cd fuzz && cargo fmt --check)
cargo check --manifest-path fuzz/Cargo.toml --locked

step "benches: every criterion bench once, quickly (they must not rot)"
cargo bench --workspace --locked -- --test

step "docs: rustdoc without warnings"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --locked

step "firmware: clippy, build (the template firmware too), and the shared test vectors on QEMU mps2-an386 (Cortex-M4F)"
(cd embedded && cargo clippy --workspace --release --locked -- -D warnings)
(cd embedded && cargo build --workspace --release --locked && cargo run --release --locked --bin vectors)

step "firmware: without LTO, a minimal firmware links no panic or formatting code (llvm-nm) and keeps its empty tables in .bss"
./scripts/check-firmware-link.sh

step "firmware in C: drift-core-ffi's static library (no LTO) and its C example replay the shared test vectors on QEMU, linking no panic or formatting code"
./scripts/check-c-example.sh

step "firmware: executed instructions per 3-axis sample, gated per model and rate (deterministic; ceilings in scripts/count-instructions.py, figures in docs/embedded.md)"
python3 scripts/count-instructions.py --gate

step "Python: drift-py in a fresh venv (pip install, pytest, stubtest, mypy, ruff, examples) and the mcap read test"
./scripts/check-python.sh

step "main job: README's demo command (--force: a re-run replaces the earlier demo, so the script stays re-runnable)"
cargo run --release --locked -- demo --quiet --force

printf '\nAll checks passed.\n'
