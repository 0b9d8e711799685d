#!/usr/bin/env bash
# The Python package (python/): builds and installs it into a fresh virtualenv with pip (maturin,
# on the root's release build: only pyo3 and the binding compile), then runs its pytest suite
# against the release CLI. Fails on any error.
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
