#!/usr/bin/env bash
# The Python package's tests on a fresh machine: a venv in target/python-venv with the pinned
# test tools (python/requirements-test.txt), the wheel built by maturin (release, abi3) and
# installed into it, the CLI built for the comparisons, then pytest on python/tests/.
#
#   bash scripts/python-test.sh            # extra arguments go to pytest, e.g. -k dask
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$root/target}
venv=$CARGO_TARGET_DIR/python-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
rm -rf "$CARGO_TARGET_DIR/wheels"
(cd python && "$venv/bin/maturin" build --release --quiet -o "$CARGO_TARGET_DIR/wheels")
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps \
    "$CARGO_TARGET_DIR"/wheels/drumroll-*.whl
cargo build --release --quiet -p drumroll
export DRUMROLL_BIN=$CARGO_TARGET_DIR/release/drumroll
# From a directory without a `drumroll` folder, so that the installed module is imported.
cd python/tests
"$venv/bin/python" -m pytest -q "$@" .
