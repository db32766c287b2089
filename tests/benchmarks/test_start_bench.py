"""The start-up benchmark cannot rot: one repetition prints a row per way of starting, with
figures (no timing is checked)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT


@pytest.mark.timeout(300)
def test_the_start_bench_prints_a_row_per_way_of_starting() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "start_bench.py"), "--reps", "1", "--no-pin"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=280,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    figure = r"\d+\.\d{3} \(\d+\.\d{3}\.\.\d+\.\d{3}\)"
    for way in ("as a user starts it", "--page-process", "--no-viewer", "command port alone"):
        row = next((line for line in done.stdout.splitlines() if line.startswith(way)), "")
        assert re.fullmatch(rf"{re.escape(way)} +{figure} +{figure} *.*", row), done.stdout
    assert re.search(r"as a user starts it .*<= 1 s: (met|NOT met)", done.stdout), done.stdout
