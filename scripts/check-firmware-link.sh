#!/usr/bin/env bash
# Builds embedded/'s `minimal` firmware with cargo's release defaults (no LTO, 16 codegen units),
# runs it on QEMU, and fails if it links any panic or formatting code, or if its empty tables are
# not zero-initialised (.bss) but copied from flash (.data). Prints its flash and RAM.
set -euo pipefail
cd "$(dirname "$0")/../embedded"
BIN="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | awk '/^host:/ {print $2}')/bin"
ELF=target/thumbv7em-none-eabihf/release-no-lto/minimal
cargo build --profile release-no-lto --locked -q --bin minimal
cargo run --profile release-no-lto --locked -q --bin minimal

symbols="$("$BIN/llvm-nm" --demangle "$ELF")"
if grep -E 'core::panicking|panic_fmt|core::fmt|panic_bounds_check' <<<"$symbols"; then
    echo "error: $ELF (release, no LTO) links the panic or formatting code above" >&2
    exit 1
fi
tables="$("$BIN/llvm-nm" --demangle --print-size "$ELF" | grep -E '::TABLES(::|$)' || true)"
if ! grep -qE ' [bB] ' <<<"$tables"; then
    echo "error: the empty tables of $ELF are not in .bss: ${tables:-symbol TABLES not found}" >&2
    exit 1
fi
"$BIN/llvm-size" -A "$ELF" | awk '
    $1 == ".text" || $1 == ".rodata" || $1 == ".vector_table" {flash += $2}
    $1 == ".data" {flash += $2; ram += $2}
    $1 == ".bss" || $1 == ".uninit" {ram += $2}
    $1 ~ /^\.(text|rodata|data|bss)$/ {printf "%-8s %7d B\n", $1, $2}
    END {printf "minimal firmware, no LTO: flash %d B, RAM %d B (stack not included); no panic or formatting code; tables in .bss\n", flash, ram}'
