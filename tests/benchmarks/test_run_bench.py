"""The benchmark script cannot rot: ``benchmarks/run.py --quick`` prints its whole table.

No timing is checked here (the figures depend on the machine); only that every
row is measured for c2rviz and for the ceiling, and that the script exits cleanly.
"""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from support import ROOT

ROWS = [
    "1 pipelined, 1 client",
    "1 pipelined: server CPU",
    "2 request/reply p50",
    "2 request/reply p99",
    "3 50 clients",
    "3 50 clients p99",
    "4 command->frame p50",
    "4 command->frame p99",
    "5 flood: viewer frames",
    "5 flood: TCP meanwhile",
    "6 launch->port open",
    "6 launch->scene ready",
    "6 RSS after start",
    "6 RSS after 100k cmds",
]
NUMBER = r"[0-9][0-9,]*(\.[0-9]+)?"


def quick_table(
    script: str, timeout_s: float, size: str = "--quick"
) -> tuple[str, dict[str, list[str]]]:
    """Run ``benchmarks/SCRIPT --quick`` (or ``--smoke``, the least work that fills every
    row, where the script has it); its output and its table's rows by first cell."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / script), size],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout_s,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith("machine: "), done.stdout
    cells = {}
    for line in done.stdout.splitlines():
        if line.startswith("| "):
            row = [cell.strip() for cell in line.strip("|").split("|")]
            cells[row[0]] = row
    return done.stdout, cells


@pytest.mark.timeout(600)
def test_quick_run_prints_every_row() -> None:
    stdout, cells = quick_table("run.py", 540, "--smoke")
    for label in ROWS:
        assert label in cells, f"row {label!r} missing from:\n{stdout}"
        _, unit, ours, ceiling, ratio, _target, _met = cells[label]
        assert unit, label
        assert re.fullmatch(NUMBER, ours), f"{label}: c2rviz figure {ours!r}"
        assert re.fullmatch(NUMBER, ceiling), f"{label}: ceiling figure {ceiling!r}"
        assert re.fullmatch(NUMBER, ratio), f"{label}: ratio {ratio!r}"


def test_the_many_robots_benchmark_prints_its_rows():
    """benchmarks/many_robots.py --smoke runs a cell of 2 with a page and prints every row
    (no timing is checked)."""
    stdout, cells = quick_table("many_robots.py", 600, "--smoke")
    for row in (
        "server CPU [cores]",
        "page frames/s, lowest robot",
        "page frames/s, median robot",
        "bystander where p99 [ms]",
    ):
        assert re.fullmatch(r"\d+\.\d\d", cells[row][1]), stdout
