"""``benchmarks/testing_bench.py --smoke`` prints every row (no timing is checked: the figures
depend on the machine; only that each row has a number)."""

from __future__ import annotations

import re
import sys

import pytest
from support import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))

from test_run_bench import quick_table  # noqa: E402

ROWS = [
    "1 where: raw socket",
    "1 where: Client",
    "1 where: client CPU, raw",
    "1 where: client CPU, Client",
    "1 where: Client/raw",
    "1 joints: raw socket",
    "1 joints: Client",
    "1 joints: client CPU, raw",
    "1 joints: client CPU, Client",
    "1 joints: Client/raw",
    "2 virtual: 1 robot moving",
    "2 virtual: 1 robot moving: server CPU",
    "2 virtual: 8 robots moving",
    "2 virtual: 8 robots moving: server CPU",
]


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    stdout, cells = quick_table("testing_bench.py", 540, "--smoke")
    for label in ROWS:
        assert label in cells, f"row {label!r} missing from:\n{stdout}"
        _, unit, figure, _goal, _met = cells[label]
        assert unit and re.fullmatch(r"[0-9.e+-]+", figure), f"{label}: {figure!r}"
