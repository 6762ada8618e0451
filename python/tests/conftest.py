"""Shared helpers: the `drumroll` CLI binary, run for the JSON the Python results must equal."""

import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli_binary():
    """The release CLI (`cargo build --release -p drumroll`), or $DRUMROLL_BIN."""
    path = os.environ.get("DRUMROLL_BIN")
    if path:
        return pathlib.Path(path)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "drumroll"


def run_cli(*args, check=True):
    """Run the CLI; returns the completed process (text output)."""
    binary = cli_binary()
    if not binary.exists():
        pytest.fail(f"{binary} not found: run `cargo build --release -p drumroll` first")
    result = subprocess.run(
        [str(binary), *args], capture_output=True, text=True, timeout=300
    )
    if check and result.returncode != 0:
        pytest.fail(f"drumroll {' '.join(args)} failed: {result.stderr}")
    return result


def cli_json(*args):
    """The CLI's JSON output, parsed by Python's json (exact floats)."""
    return json.loads(run_cli(*args).stdout)


def cli_error(*args):
    """The CLI's error as the Python module words it: the error and its causes joined by
    ': ' (the CLI prints `drumroll: error: E` and `  caused by: C` lines)."""
    result = run_cli(*args, check=False)
    assert result.returncode != 0, f"drumroll {' '.join(args)} should fail"
    parts = []
    for line in result.stderr.splitlines():
        if line.startswith("drumroll: error: "):
            parts.append(line[len("drumroll: error: "):])
        elif line.startswith("  caused by: "):
            parts.append(line[len("  caused by: "):])
    return ": ".join(parts)
