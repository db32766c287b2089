"""docs/rosbridge.md's roslibpy example runs as written against the program.

The example is taken from the page (the first ``python`` block under "A roslibpy
example") and run with the installed roslibpy, its default transport, against
``c2rviz --rosbridge-port 0``: only the port is changed from 9090.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from support import ROOT
from test_rosbridge_door import read_until

WAIT_S = 120.0


def example() -> str:
    page = (ROOT / "docs" / "rosbridge.md").read_text()
    section = page.split("## A roslibpy example", 1)[1]
    found = re.search(r"```python\n(.*?)```", section, re.DOTALL)
    assert found is not None, "no python block under 'A roslibpy example'"
    return found[1]


def test_the_roslibpy_example_runs_as_written(c2rviz_process, tmp_path: Path) -> None:
    proc = c2rviz_process("--no-viewer", "--rosbridge-port", "0")
    port = read_until(proc, r"rosbridge at ws://127\.0\.0\.1:(\d+)/")[1]
    code = example()
    assert "port=9090" in code
    script = tmp_path / "example.py"
    script.write_text(code.replace("port=9090", f"port={port}"))
    done = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=WAIT_S
    )
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert lines[:2] == ["True", "joint_s 0.0"], done.stdout
    # The subscriber prints from roslibpy's thread while the main thread prints the
    # replies: a print's text and its newline are two writes, so under load two prints can
    # share a line (seen once in a full run). Each text is one write: count those.
    assert done.stdout.count("{'reply': 'ok', 'ok': True}") == 2, done.stdout  # joints, wait
    assert "{'reply': 'ok 0.6,0.3,0.3,0.4,0.5,0.6,0.7', 'ok': True}" in done.stdout
