#!/usr/bin/env bash
# The Python package's CI: builds the wheel into a fresh venv under target/
# (sharing the workspace's target directory, so the library's dependencies
# build once for the CLI and the wheel), builds the CLI the tests compare
# against, and runs pytest. Needs Rust, CPython >= 3.9 with venv and pip,
# and crates.io and PyPI. Run from anywhere: `bash python/ci.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="$PWD/target"
python="${PYTHON:-python3}"
venv="$CARGO_TARGET_DIR/pyenv"
started=$(date +%s)

rm -rf "$venv"
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade pip
cargo build --release --bin tessera
"$venv/bin/python" -m pip install ./python pytest numpy
# healpy for the cross-checks of python/tests/test_healpy.py, which are
# skipped without it: a failed install does not fail CI
"$venv/bin/python" -m pip install --quiet healpy \
    || echo "python/ci.sh: healpy did not install; its cross-checks will be skipped"
"$venv/bin/python" -m pytest python/tests
echo "python/ci.sh: $(( $(date +%s) - started )) s"
