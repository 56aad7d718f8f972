"""Shared fixtures: the repository's data and the subfric program to compare against.

The program is the one named by SUBFRIC_BIN (tests/e2e/python.rs passes the subfric program
that cargo built for that test run; by hand: `cargo build --release` and
SUBFRIC_BIN=target/release/subfric). No test looks for a program of its own accord, so none
can compare against a stale one.
"""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXPERIMENTS = REPO / "experiments"
GOLDEN = REPO / "tests" / "golden"
BUNDLED = sorted(p.name for p in EXPERIMENTS.iterdir() if (p / "experiment.json").is_file())


def _program():
    p = os.environ.get("SUBFRIC_BIN")
    if not p:
        pytest.fail(
            "SUBFRIC_BIN is not set: these tests compare the package with the subfric program "
            "(cargo build --release, then SUBFRIC_BIN=target/release/subfric)",
            pytrace=False,
        )
    if not os.access(p, os.X_OK):
        pytest.fail(f"SUBFRIC_BIN={p}: not an executable program", pytrace=False)
    return p


class Cli:
    """Runs the subfric program."""

    def __init__(self, program):
        self.program = program

    def run(self, *args, ok=True):
        r = subprocess.run(
            [self.program, *map(str, args), "--progress", "never"]
            if args and args[0] in ("fit", "diagnose")
            else [self.program, *map(str, args)],
            capture_output=True,
            text=True,
            timeout=600,
        )
        if ok and r.returncode != 0:
            raise AssertionError(f"subfric {' '.join(map(str, args))} failed:\n{r.stderr}")
        if not ok and r.returncode == 0:
            raise AssertionError(f"subfric {' '.join(map(str, args))} succeeded (expected an error)")
        return r

    def json(self, path):
        with open(path) as f:
            return json.load(f)


@pytest.fixture(scope="session")
def cli():
    return Cli(_program())


def set_cell(csv, line, column, value):
    """Writes `value` into one cell of a CSV: 1-based line, column by header name."""
    lines = csv.read_text().splitlines(keepends=True)
    header = next(l for l in lines if not l.startswith("#")).strip().split(",")
    cells = lines[line - 1].rstrip("\n").split(",")
    cells[header.index(column)] = value
    lines[line - 1] = ",".join(cells) + "\n"
    csv.write_text("".join(lines))


@pytest.fixture
def copy_set(tmp_path):
    """A copy of a bundled (or golden) set in a temporary folder, to corrupt."""

    def copy(name, root=EXPERIMENTS):
        dst = tmp_path / name
        shutil.copytree(root / name, dst)
        return dst

    return copy
