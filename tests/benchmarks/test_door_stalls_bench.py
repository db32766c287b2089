"""``benchmarks/door_stalls_bench.py --smoke`` (every row, a quarter of a second each after a
quarter of flooding: the least work) prints every row with its figures (no timing is
judged)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT

ROWS = (
    "bystander, no flood:",
    "bystander, 4 x 1 MiB CRCL flood:",
    "bystander, 4 x 8000-point traj. refused at a joint name:",
    "bystander, 4 x 8000-point traj. refused by its check:",
)
FIGURES = re.compile(r"p50 [0-9.]+ ms, p99 [0-9.]+ ms, max [0-9.]+ ms \(goal p99 <= 5\)")


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "door_stalls_bench.py"), "--smoke"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=540,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("machine: ")
    lines = done.stdout.splitlines()
    for label in ROWS:
        line = next((line for line in lines if line.startswith(label)), None)
        assert line is not None, f"row {label!r} missing from:\n{done.stdout}"
        assert FIGURES.search(line), line
