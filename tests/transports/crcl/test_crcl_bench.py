"""The codec benchmark cannot rot: its quick run prints every row (no timing is judged)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[3] / "benchmarks" / "crcl_codec_bench.py"
ROWS = [
    "parse MoveTo",
    "write full status",
    "parse GetStatus",
    "write compact status",
    "split MoveTo (one feed)",
    "split 1 MiB, 64 KiB chunks",
    "split 1 MiB, 1 KiB chunks",
]


def test_quick_run_prints_every_row(capsys: pytest.CaptureFixture[str]) -> None:
    spec = importlib.util.spec_from_file_location("crcl_codec_bench", SCRIPT)
    assert spec is not None and spec.loader is not None
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("machine: ")
    cells = {
        row[0]: row
        for line in out.splitlines()
        if line.startswith("| ")
        for row in [[cell.strip() for cell in line.strip("|").split("|")]]
    }
    for label in ROWS:
        assert re.fullmatch(r"[0-9]+(\.[0-9])?", cells[label][2]), cells[label]
    for label in ROWS[:2]:
        assert cells[label][5] == "<= 200 us" and cells[label][6] in ("yes", "no")
