"""The guard benchmark cannot rot: ``benchmarks/guard_bench.py --smoke`` prints every row.

No timing is judged (the figures depend on the machine); only that each row has a figure.
"""

from __future__ import annotations

import re

import pytest
from test_run_bench import quick_table

ROWS = [
    "bystander `where` while 10 clients loop guarded `rand`, 100 objects p99",
    "bystander `where` while 10 clients loop guarded `joints`, 100 objects p99",
    "guarded `rand` answered meanwhile",
    "rest after `stop`, guarded move at speed 100",
    "rest after `stop`, guarded move at speed 20",
    "rest after `stop`, guarded move at speed 5",
    "`plan joints` round trip p50 (box in the way)",
    "`plan joints` round trip p95",
]


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    stdout, cells = quick_table("guard_bench.py", 540, "--smoke")
    for label in ROWS:
        assert label in cells, f"row {label!r} missing from:\n{stdout}"
        assert re.fullmatch(r"[0-9]+(\.[0-9]+)?", cells[label][1]), cells[label]
    assert "refused" not in stdout and "  plan " not in stdout
