"""The instruments benchmark cannot rot: ``benchmarks/instruments_bench.py --smoke`` (the
least work that still fills every row) prints every row with a figure (no figure is judged
here: they depend on the machine)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT

ROWS = [
    "1 robot: frames/s to a tab, plots on",
    "1 robot: CPU the plots add",
    "8 robots: frames/s to a tab, plots on",
    "8 robots: server CPU, plots off",
    "8 robots: CPU the plots add",
    "recorded page: size per minute past viser's page",
    "record stop, 10 s (smoke) at 100 Hz: time",
    "record stop, 10 s (smoke): extra memory",
]
NUMBER = r"-?[0-9][0-9,]*(\.[0-9]+)?"


@pytest.mark.timeout(900)
def test_quick_run_prints_every_row() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "instruments_bench.py"), "--smoke"]
        + ["--no-browser"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=840,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith("machine: "), done.stdout
    cells = {}
    for line in done.stdout.splitlines():
        if line.startswith("| "):
            row = [cell.strip() for cell in line.strip("|").split("|")]
            cells[row[0]] = row
    for label in ROWS:
        found = [key for key in cells if key.startswith(label)]
        assert found, f"row {label!r} missing from:\n{done.stdout}"
        _, unit, figure, _goal, _met = cells[found[0]]
        assert unit and re.fullmatch(NUMBER, figure), cells[found[0]]
