#!/usr/bin/env bash
# The Python module's checks, from a really clean state: a fresh venv in .venv-check/ (deleted and
# recreated on every run), `pip install ./crates/drift-py[test,plot,distributed]` (a real PEP 517
# build through maturin, with matplotlib, pandas, mcap, mcap-ros2-support and dask so the optional
# paths run), then pytest (with the CLI binary, to compare simulated bytes), the benchmark scripts at
# their tiny size (a check that they still run and that what they compare agrees; timings printed,
# never asserted), mypy's stubtest, a strict type check of the package's Python code, the examples
# and the benchmarks, ruff, and the examples themselves. Prints how long each step took. Safe to
# re-run; meant to be called from scripts/check.sh (the single test command).
#
# Needs: python3 >= 3.9 (with venv; installed via apt-get if missing), Rust (cargo), and PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=.venv-check
PYTHON=${PYTHON:-python3}
declare -a TIMES=()

now() { echo "$EPOCHREALTIME"; }
step() {
    local name=$1
    shift
    printf '\n=== %s\n' "$name"
    local start
    start=$(now)
    "$@"
    TIMES+=("$(awk -v a="$start" -v b="$(now)" -v n="$name" 'BEGIN { printf "%7.1f s  %s", b - a, n }')")
}

make_venv() {
    rm -rf "$VENV"
    if ! "$PYTHON" -m venv "$VENV" 2>/dev/null; then
        # Debian/Ubuntu ship venv (ensurepip) separately.
        rm -rf "$VENV"
        local sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        version=$("$PYTHON" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
        $sudo apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "python${version}-venv" >/dev/null
        "$PYTHON" -m venv "$VENV"
    fi
    "$VENV/bin/python" --version
    "$VENV/bin/python" -m pip install --quiet --upgrade pip
}

install_package() {
    # Builds the abi3 wheel with maturin (fetched by pip into an isolated build environment) and
    # installs it with its test tools (pytest, hypothesis, mypy, ruff, pandas, mcap,
    # mcap-ros2-support, rosbags), the plot extra (matplotlib) and the distributed extra (dask[distributed]);
    # numpy is a runtime dependency.
    "$VENV/bin/python" -m pip install --quiet "./crates/drift-py[test,plot,distributed]"
    "$VENV/bin/python" -c 'import gyrodrift, numpy, pandas, matplotlib, dask; print("gyrodrift", gyrodrift.__version__, "from", gyrodrift.__file__, "| numpy", numpy.__version__, "| pandas", pandas.__version__, "| matplotlib", matplotlib.__version__, "| dask", dask.__version__)'
}

build_cli() {
    # The command line, for the test that `gyrodrift simulate` and `gyrodrift.simulate` write the
    # same bytes, and for the Python mcap reader test below.
    cargo build --quiet --release --locked -p gyrodrift
}

run_pytest() {
    # From the repository root, so `import gyrodrift` is the installed wheel, not the source tree.
    GYRODRIFT_BIN=target/release/gyrodrift "$VENV/bin/python" -m pytest crates/drift-py/tests -q -p no:cacheprovider --durations=5
}

run_benches() {
    # Every bench script at its tiny size (`--tiny`, which each must accept): outputs checked
    # against gyrodrift's, timings only printed. The pure-Rust reference example is built first,
    # outside the scripts' output.
    cargo build --quiet --release --locked --example correct_throughput
    for script in crates/drift-py/bench/bench_*.py; do
        echo "--- $script --tiny"
        "$VENV/bin/python" "$script" --tiny
    done
}

run_stubtest() {
    "$VENV/bin/python" -m mypy.stubtest gyrodrift._gyrodrift \
        --allowlist crates/drift-py/stubtest-allowlist.txt
}

run_mypy_examples() {
    "$VENV/bin/python" -m mypy --strict --no-incremental crates/drift-py/examples crates/drift-py/bench
    # The package's own Python (plot.py, tables.py, __init__.py) against the hand-written stubs.
    (cd crates/drift-py/python && "../../../$VENV/bin/python" -m mypy --strict --no-incremental -p gyrodrift)
}

run_ruff() {
    "$VENV/bin/ruff" check crates/drift-py
    "$VENV/bin/ruff" format --check crates/drift-py
}

run_recording_read_test() {
    # The Python `mcap` package must read what `gyrodrift simulate` writes (mcap-ros2-support comes
    # with the package's [test] extra).
    GYRODRIFT_BIN=target/release/gyrodrift "$VENV/bin/python" -m pytest crates/drift-sim/tests/python -q -p no:cacheprovider
}

run_examples() {
    for script in crates/drift-py/examples/*.py; do
        echo "--- $script"
        MPLBACKEND=Agg "$VENV/bin/python" "$script"
    done
}

"$PYTHON" --version
command -v cargo >/dev/null || { echo "cargo not found: install Rust (rustup) first" >&2; exit 1; }
step "fresh venv in $VENV" make_venv
step "pip install ./crates/drift-py[test,plot,distributed] (maturin build)" install_package
step "cargo build --release -p gyrodrift (the CLI)" build_cli
step "pytest crates/drift-py/tests" run_pytest
step "bench scripts at tiny size" run_benches
step "stubtest gyrodrift._gyrodrift" run_stubtest
step "mypy --strict examples, bench and the package" run_mypy_examples
step "ruff check and format --check" run_ruff
step "examples" run_examples
step "Python mcap reads gyrodrift recordings" run_recording_read_test

printf '\n=== timings\n'
printf '%s\n' "${TIMES[@]}"
printf '\nPython checks passed.\n'
