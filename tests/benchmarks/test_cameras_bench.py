"""The cameras benchmark cannot rot: one quick run prints a figure for each row.

No timing is judged (the figures depend on the machine).
"""

from __future__ import annotations

import re
import sys

import pytest
from support import ROOT


def test_quick_run_prints_every_row(capsys: pytest.CaptureFixture[str]) -> None:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import cameras_bench
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    assert cameras_bench.main(["--repeat", "1", "--looks", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3
    for count, line in zip((0, 10, 100), lines):
        assert re.match(rf"a look, 100 parts, +{count} objects: +[0-9.]+ ms, \d+ seen", line), line
