#!/usr/bin/env bash
# Prints every figure of docs/embedded.md: vectors on QEMU (state size, stack), flash footprint by
# difference of builds, and executed instructions per 3-axis sample.
set -euo pipefail
cd "$(dirname "$0")/../embedded"
SIZE="$(rustc --print sysroot)/lib/rustlib/x86_64-unknown-linux-gnu/bin/llvm-size"
cargo build --release --locked -q
echo "## QEMU run of the shared vectors (cargo run --release --bin vectors)"
cargo run --release --locked -q --bin vectors
echo
echo "## Flash footprint (.text and .rodata, bytes; opt-level 3, LTO)"
text() { "$SIZE" -A "target/thumbv7em-none-eabihf/release/$1" | awk -v s="$2" '$1==s {print $2}'; }
base=$(text footprint_base .text); dec=$(text footprint_decode .text); cor=$(text footprint_correct .text)
echo "runtime only (footprint_base)       .text $base"
echo "image decoder + validation          .text $((dec - base))   (footprint_decode − footprint_base)"
echo "corrector (power_on + correct)      .text $((cor - dec))   (footprint_correct − footprint_decode)"
echo "CRC-32 table and constants          .rodata $(( $(text footprint_decode .rodata) - $(text footprint_base .rodata) ))"
echo "vectors firmware total              .text $(text vectors .text)  .rodata $(text vectors .rodata)"
echo
cd ..
python3 scripts/count-instructions.py
