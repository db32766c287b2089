"""The plugin's xdist benchmark cannot rot: ``benchmarks/plugin_xdist.py --smoke`` runs its
generated suite with 1 and 2 workers and prints every row (no timing is judged here)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT


@pytest.mark.timeout(600)
def test_quick_run_prints_both_times_and_the_ratio() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "plugin_xdist.py"), "--smoke"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=540,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith("machine: "), done.stdout
    for label in ("plugin tests, pytest -n 1", "plugin tests, pytest -n 2", "2 workers vs 1"):
        row = [line for line in done.stdout.splitlines() if label in line]
        assert row, f"row {label!r} missing from:\n{done.stdout}"
        figure = row[0].strip("|").split("|")[2].strip()
        assert re.fullmatch(r"[0-9]+\.[0-9]+", figure), row
