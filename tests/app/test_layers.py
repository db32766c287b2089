"""The house in layers (issue 22): the import contracts hold, and a program without a
viewer never loads viser."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys

from support import ROOT

NO_VIEWER_RUN = """
import sys
from c2rviz.app.cli import main
status = main(["--no-viewer", "--port", "0"])
loaded = sorted(m for m in ("viser", "msgspec", "c2rviz.view") if m in sys.modules)
print("loaded:", ",".join(loaded) or "none", flush=True)
sys.exit(status)
"""


def test_a_program_without_a_viewer_never_loads_viser():
    proc = subprocess.Popen(
        [sys.executable, "-c", NO_VIEWER_RUN],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert proc.stdout is not None
    with proc.stdout:
        lines = []
        for line in proc.stdout:
            lines.append(line)
            if re.search(r"commands on [\d.]+:\d+", line):
                break
        else:
            raise AssertionError("c2rviz did not start:\n" + "".join(lines))
        proc.send_signal(signal.SIGTERM)
        rest = proc.stdout.read()
    assert proc.wait(timeout=60) == 0, rest
    assert "loaded: none" in rest, rest


def test_the_import_contracts_hold():
    """import-linter's contracts (pyproject.toml): the layers, what the clients and the
    protocol may import, and no import cycle at any depth (TYPE_CHECKING imports count)."""
    linter = os.path.join(os.path.dirname(sys.executable), "lint-imports")
    done = subprocess.run(
        [linter, "--no-cache"], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 broken" in done.stdout or "Contracts: 3 kept, 0 broken" in done.stdout, done.stdout
