"""The fairness benchmark cannot rot: ``benchmarks/fairness.py --smoke`` prints every row.

No timing is judged (the figures depend on the machine, and rows that other branches
fix may say NOT MET); only that each row is there with a figure, a goal and a verdict.
"""

from __future__ import annotations

import re

import pytest
from test_run_bench import quick_table

ROWS = [
    "bystander `ik` while one client plans into the chimney",
    "bystander guarded `joints` meanwhile",
    "ten clients' plans into the chimney at once",
    "bystander `where` during a CRCL MoveThroughTo",
    "bystander `where` during a CRCL document flood",
    "bystander `where` during a rosbridge /joint_trajectory",
]


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    stdout, cells = quick_table("fairness.py", 540, "--smoke")
    for label in ROWS:
        assert label in cells, f"row {label!r} missing from:\n{stdout}"
        _, figure, goal, verdict = cells[label]
        assert re.search(r"\d", figure) and re.search(r"\d", goal), cells[label]
        assert verdict in ("met", "NOT MET"), cells[label]
    assert "error: no path found" in stdout, "the chimney's plan searched its whole time"
