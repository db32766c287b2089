"""The bag benchmarks cannot rot: each quick run prints every row (no timing is checked)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from support import ROOT


def quick(script: str, *flags: str, timeout: float) -> list[list[str]]:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / script), "--quick", *flags],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return [line.split() for line in done.stdout.splitlines() if line.strip()]


@pytest.mark.timeout(300)
def test_the_recording_cost_prints_a_row_per_cell() -> None:
    rows = quick("bag_record_bench.py", "--seconds", "0.5", timeout=280)
    table = [row for row in rows if len(row) == 7 and row[0] in ("1", "8")]
    assert [row[0] for row in table] == ["1", "8"], rows
    for row in table:  # moving, txt+csv, +bag, bag adds, goal: each a share of a core
        assert all(cell.endswith("%") for cell in row[1:6]), row


@pytest.mark.timeout(600)
def test_the_player_bench_prints_every_row() -> None:
    rows = quick("bag_play_bench.py", "--minutes", "1.5", timeout=580)
    first = [row for row in rows if row[:2] == ["60", "s"] or row[:1] == ["whole"]]
    assert len(first) == 4, rows  # time to the first line, then memory, for each span
    assert all(row[-1] == "MB" for row in first), first
    assert any(row[:1] == ["playing"] and "RSS" in row for row in rows), rows
