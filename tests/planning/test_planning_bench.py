"""The planning benchmark cannot rot: its quick run prints a row per arm (no timing judged)."""

from __future__ import annotations

import re
import subprocess
import sys

from planning_scenes import ROOT


def test_quick_benchmark_prints_its_table() -> None:
    done = subprocess.run(
        [sys.executable, "benchmarks/planning_bench.py", "--quick", "--robots", "kuka_lwr"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout
    assert out.startswith("machine: ")
    number = r"[0-9][0-9,]*\.?[0-9]*"
    row = rf"\| kuka_lwr \| {number} \| {number} \| {number} \| {number} \| (yes|NO) \|"
    assert re.search(row, out), out
    assert "no path: 0" in out
    assert "leaked" not in done.stderr  # nanobind's complaint at exit, if OMPL objects lived on
