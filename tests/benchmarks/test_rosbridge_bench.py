"""``benchmarks/rosbridge_bench.py --quick`` prints a row for every subscriber count (here 0,
1 and 3, half a second each: the least work that fills every column).

No timing is checked (the figures depend on the machine): only that the real
server, the subscribers and the text-port driver ran and every row has numbers.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from support import ROOT


@pytest.mark.timeout(300)
def test_quick_run_prints_every_row() -> None:
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "rosbridge_bench.py"), "--quick"]
        + ["--counts", "1,3", "--seconds", "0.5"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=280,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith("machine: "), done.stdout
    rows = {}
    for line in done.stdout.splitlines():
        if line.startswith("| ") and not line.startswith("| subscribers"):
            cells = [cell.strip() for cell in line.strip("|").split("|")]
            rows[cells[0]] = cells
    assert sorted(rows) == ["0", "1", "3"], done.stdout
    for count in ("1", "3"):
        msgs, frames, _, cpu = (float(x) for x in rows[count][1:5])
        assert msgs > 0 and frames > 0 and cpu > 0, rows[count]
        leave_p99, text_p99 = float(rows[count][7]), float(rows[count][11])
        assert leave_p99 >= 0 and text_p99 > 0, rows[count]  # measured, not NaN
