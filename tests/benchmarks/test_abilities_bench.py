"""The abilities benchmark cannot rot: ``benchmarks/abilities.py --smoke`` prints its whole table.

No timing is checked (the figures depend on the machine); only that every row
has a figure and a load average, and that the script exits cleanly.
"""

from __future__ import annotations

import re
import sys

import pytest
from support import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))

from abilities import ROWS  # noqa: E402
from test_run_bench import quick_table  # noqa: E402

NUMBER = r"[0-9][0-9,]*(\.[0-9]+)?"


@pytest.mark.timeout(900)
def test_quick_run_prints_every_row() -> None:
    stdout, cells = quick_table("abilities.py", 840, "--smoke")
    cell_left_out = "row 4 left out" in stdout
    for key, label, *_ in ROWS:
        if key.startswith("cell_") and cell_left_out:
            assert label not in cells, label
            continue
        assert label in cells, f"row {label!r} missing from:\n{stdout}"
        _, unit, median, load, _note = cells[label]
        assert unit, label
        assert re.fullmatch(NUMBER, median), f"{label}: figure {median!r}"
        assert re.fullmatch(rf"{NUMBER}(\.\.{NUMBER})?", load), f"{label}: load {load!r}"
