"""benchmarks/bag_bench.py cannot rot: its quick run prints every row (no timing is checked)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from ros_helpers import ROOT


@pytest.mark.timeout(300)
def test_quick_run_prints_every_row() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bag_bench.py"), "--quick", "--minutes", "0.2"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=280,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    rows = [line.split() for line in done.stdout.splitlines() if line.strip()]
    written = [row for row in rows if len(row) == 6 and row[0] in ("1", "8")]
    assert [row[0] for row in written] == ["1", "8"], done.stdout
    spans = [row for row in rows if row[:2] == ["60", "s"] or row[:1] == ["whole"]]
    assert len(spans) == 2, done.stdout
    for row in spans:  # open, check, first, goal, all, samples, RSS at open, peak RSS
        assert row[-1] == "MB" and row[-3] == "MB", row
