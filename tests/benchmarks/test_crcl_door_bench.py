"""The CRCL door benchmark cannot rot: ``benchmarks/crcl_bench.py --quick`` prints every
row with a figure in each column it fills (no timing is judged)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT

ROWS = {
    "1 round trip p50 [ms]": 2,
    "1 round trip p99 [ms]": 2,
    "2 10 clients at 100 Hz [answers/s]": 2,
    "2 round trip p99 under it [ms]": 2,
    "3 parse a MoveTo [us]": 1,
    "3 write a full status [us]": 1,
}
NUMBER = r"[0-9]+(\.[0-9]+)?"


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "crcl_bench.py"), "--quick"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=540,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("machine: ")
    cells = {
        row[0]: row
        for line in done.stdout.splitlines()
        if line.startswith("| ")
        for row in [[cell.strip() for cell in line.strip("|").split("|")]]
    }
    for label, figures in ROWS.items():
        assert label in cells, f"row {label!r} missing from:\n{done.stdout}"
        for cell in cells[label][1 : 1 + figures]:
            assert all(re.fullmatch(NUMBER, part) for part in cell.split(" / ")), (label, cell)
    for label in ("1 round trip p99 [ms]", "3 parse a MoveTo [us]", "3 write a full status [us]"):
        assert cells[label][4] in ("yes", "no"), cells[label]
