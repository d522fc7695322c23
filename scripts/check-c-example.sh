#!/usr/bin/env bash
# The C interface end to end: builds drift-core-ffi's static library for the Cortex-M4F (cargo's
# release profile: no LTO), compiles the C example against it with arm-none-eabi-gcc (hard float),
# and replays the shared test vectors on QEMU's mps2-an386; QEMU's exit status is the verdict.
# Then checks the linked firmware carries no panic or formatting code (llvm-nm).
# Needs: the thumbv7em-none-eabihf target, llvm-tools, gcc-arm-none-eabi, libnewlib-arm-none-eabi,
# qemu-system-arm (scripts/check.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."

example=crates/drift-core-ffi/examples/c
out=target/c-example
mkdir -p "$out"

cargo build -p drift-core-ffi --target thumbv7em-none-eabihf --release --locked
python3 "$example/vectors_to_c.py" testdata/vectors.json "$out/vectors.c"
arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
    -std=c11 -O2 -Wall -Wextra -Werror -ffunction-sections -fdata-sections \
    -I crates/drift-core-ffi/include -I "$example" \
    "$example/main.c" "$example/startup.c" "$out/vectors.c" \
    -T "$example/mps2-an386.ld" -nostartfiles --specs=nano.specs --specs=rdimon.specs \
    -Wl,--gc-sections -Wl,--no-warn-execstack \
    target/thumbv7em-none-eabihf/release/libdrift_core_ffi.a -lm \
    -o "$out/c-example.elf"

qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
    -semihosting-config enable=on,target=native -kernel "$out/c-example.elf"

BIN="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | awk '/^host:/ {print $2}')/bin"
symbols="$("$BIN/llvm-nm" --demangle "$out/c-example.elf")"
# Rust's panic machinery and formatter: none of it may reach the C firmware.
if grep -E 'core::panicking|panic_fmt|core::fmt|panic_bounds_check' <<<"$symbols"; then
    echo "error: the C example links the panic or formatting code above from the static library (release, no LTO)" >&2
    exit 1
fi
"$BIN/llvm-size" "$out/c-example.elf"
echo "C example (static library built without LTO): no panic or formatting code linked"
