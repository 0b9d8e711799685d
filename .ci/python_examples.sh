#!/usr/bin/env bash
# The Python examples (examples/python/) against real outputs: creates a virtualenv, installs the
# pinned requirements from PyPI, runs a short rigid-model `rotorsim run` and the 4-case sweep
# sweeps/ci_rigid.toml, then runs each example on those outputs. Fails on any error.
# Usage: .ci/python_examples.sh [WORK_DIR]   (default: a fresh temporary folder, removed at the end)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
if [ $# -ge 1 ]; then work=$1; mkdir -p "$work"; else work=$(mktemp -d); trap 'rm -rf "$work"' EXIT; fi
python3 --version
if ! python3 -c "import ensurepip, venv" 2>/dev/null; then
    # Debian ships venv's pip bootstrap separately
    sudo=""; [ "$(id -u)" = 0 ] || sudo="sudo -n"
    $sudo apt-get update -q
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q python3-venv
fi
python3 -m venv "$work/venv"
"$work/venv/bin/python" -m pip install --quiet -r examples/python/requirements.txt
py="$work/venv/bin/python"

# The binary `cargo test --release` built: the same build (tests/one_build.rs), so this is a
# no-op after the tests, and builds the binary only when the script runs alone.
built=$SECONDS
cargo build --release --quiet
echo "rotorsim binary ready in $((SECONDS - built)) s"
bin="${CARGO_TARGET_DIR:-$root/target}/release/rotorsim"
"$bin" run --model rigid --revs 30 --out "$work/run"
"$bin" sweep sweeps/ci_rigid.toml --out "$work/sweep"

passed=0
failed=0
example() {
    echo "== examples/python/$*"
    if (cd examples/python && "$py" "$@"); then passed=$((passed + 1)); else failed=$((failed + 1)); fi
}
example summary_verdict.py "$work/run"
example last_rev_comparison.py "$work/run" "$work/png"
example sweep_plot.py "$work/sweep" "$work/png"
example mcap_comparison.py "$work/run/result.mcap" "$work/png"
for png in damper_force_last_rev.png damper_stroke_last_rev.png damper_force_mcap.png; do
    if [ ! -s "$work/png/$png" ]; then echo "missing $work/png/$png"; failed=$((failed + 1)); fi
done
echo "python_examples: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
