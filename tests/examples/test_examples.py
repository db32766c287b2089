"""The examples run as their users run them: ``examples/pick_and_place``'s own test suite in a
pytest of its own (its rootdir, its pytest.ini, the plugin), and its controller against a
server started as ``c2rviz`` is.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from support import ROOT

EXAMPLE = ROOT / "examples" / "pick_and_place"


@pytest.mark.timeout(600)
def test_the_pick_and_place_suite_passes():
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q"],
        cwd=EXAMPLE,
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert re.search(r"\b5 passed\b", out), out
    assert not (EXAMPLE / "c2rviz-recordings").exists()  # nothing failed: nothing kept


def test_the_controller_runs_against_a_server(c2rviz_process):
    process = c2rviz_process("--no-viewer", "--clock", "virtual", "--robot", "fanuc_lrmate200id")
    done = subprocess.run(
        [
            sys.executable,
            str(EXAMPLE / "controller.py"),
            "--port",
            str(process.port),
            "--parts",
            "2",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "placed 2 parts: 2/2 goals met"
