"""The examples run as their users run them: each one's own test suite in a pytest of its
own (its rootdir, its pytest.ini, the plugin), ``examples/pick_and_place``'s controller
against a server started as ``c2rviz`` is, and ``examples/crcl_kitting``'s CRCL program with
``c2rviz-play`` against ``c2rviz --config kitting.ini``.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT

from c2rviz import Client

EXAMPLE = ROOT / "examples" / "pick_and_place"
KITTING = ROOT / "examples" / "crcl_kitting"


@pytest.mark.timeout(600)
@pytest.mark.parametrize(("example", "tests"), [(EXAMPLE, 12), (KITTING, 3)], ids=["pick", "crcl"])
def test_the_example_suite_passes(example, tests):
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q"],
        cwd=example,
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert re.search(rf"\b{tests} passed\b", out), out
    assert not (example / "c2rviz-recordings").exists()  # nothing failed: nothing kept


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


def crcl_port(process) -> int:
    """The CRCL port the program's banner gives (reading on until it says it)."""
    pattern = re.compile(r"CRCL on 127\.0\.0\.1:(\d+) ")
    for line in process.output:
        if found := pattern.search(line):
            return int(found.group(1))
    assert process.popen.stdout is not None
    for line in process.popen.stdout:
        process.output.append(line)
        if found := pattern.search(line):
            return int(found.group(1))
    raise AssertionError("no CRCL line in:\n" + "".join(process.output))


def test_the_crcl_program_plays_against_a_server(c2rviz_process):
    process = c2rviz_process(
        "--no-viewer", "--clock", "virtual", "--config", str(KITTING / "kitting.ini")
    )
    port = crcl_port(process)
    with Client("127.0.0.1", process.port) as robot:  # gone while the program plays:
        for index, name in enumerate(("p1", "p2", "p3")):  # an idle client stops virtual time
            robot.goal(name, (0.40 + 0.05 * index, -0.2, 0.225, 0, 0, 0))
    done = subprocess.run(
        [
            str(Path(sys.executable).with_name("c2rviz-play")),
            str(KITTING / "kit.xml"),
            "--port",
            str(port),
            "--quiet",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "kit.xml: 28 CRCL commands, all done" in done.stdout
    with Client("127.0.0.1", process.port) as robot:
        assert robot.score() == (3, 3, ())
