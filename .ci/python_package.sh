#!/usr/bin/env bash
# The Python package (python/): builds and installs it into a fresh virtualenv with pip (maturin,
# on the root's release build: only pyo3 and the binding compile), then runs its pytest suite
# against the release CLI, then the examples written on the package. Fails on any error.
# Usage: .ci/python_package.sh [WORK_DIR]   (default: a fresh temporary folder, removed at the end)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ge 1 ]; then work=$1; mkdir -p "$work"; else work=$(mktemp -d); trap 'rm -rf "$work"' EXIT; fi
python3 -m venv "$work/venv"
py="$work/venv/bin/python"
cargo build --release --quiet
start=$SECONDS
"$py" -m pip install --quiet "./python[test]"
echo "rotorsim Python package built and installed in $((SECONDS - start)) s"
"$py" -m pytest -q python/tests
# The examples written on the package (examples/python/api_*.py), with the examples' pinned
# plotting requirements.
"$py" -m pip install --quiet -r examples/python/requirements.txt
(cd examples/python && "$py" api_orifice_study.py "$work/png" && "$py" api_damper_loops.py "$work/png")
for png in orifice_study.png damper_loops.png damper_pressures.png; do
    [ -s "$work/png/$png" ] || { echo "missing $work/png/$png"; exit 1; }
done
echo "python package examples: 2 passed"
