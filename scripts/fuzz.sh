#!/usr/bin/env bash
# Fuzzes every target for SECONDS each (default 300), then minimises its corpus in place:
#   scripts/fuzz.sh [SECONDS] [TARGET...]
# Needs nightly and cargo-fuzz (installed here if missing). Debug assertions and overflow checks are
# on (cargo-fuzz's default), so an arithmetic overflow is a finding, as it is in a test build.
# Findings land in fuzz/artifacts/<target>/; the stable replay test (crates/drift-fuzz) runs the
# committed corpora on every `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(blob recording csv corrector)
rustup toolchain install nightly --profile minimal >/dev/null 2>&1 || true
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
cd fuzz
for t in "${targets[@]}"; do
    case "$t" in
        blob) max_len=12000 ;;
        # Finding F4 (docs/reliability.md): mcap's record parser reserves a string's declared
        # length (up to 4 GiB, virtual, never touched) before reading it; libFuzzer's malloc limit
        # would report every such input. The RSS limit (2 GiB) still catches real memory use.
        recording) max_len=8192 ;;
        *) max_len=4096 ;;
    esac
    extra=()
    [ "$t" != recording ] || extra=(-malloc_limit_mb=4400)
    echo "=== $t: ${seconds} s"
    cargo +nightly fuzz run "$t" -- -max_total_time="$seconds" -max_len="$max_len" \
        -print_final_stats=1 -timeout=10 "${extra[@]}" 2>&1 | tee "target/fuzz-$t.log" | grep -E "^(#[0-9]+\s+DONE|stat::|==|SUMMARY|Done)" || true
    # Keep the committed corpus small: the smallest set of inputs that covers every feature.
    cargo +nightly fuzz cmin "$t" -- -set_cover_merge=1 -use_counters=0 "${extra[@]}" 2>&1 | tail -n 2
done
