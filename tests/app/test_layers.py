"""The house in layers (issue 22): the import contracts hold, a program without a
viewer never loads viser, and the start loads no library only later work needs."""

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


START_RUN = """
import sys
import c2rviz.app.cli, c2rviz.app.program, c2rviz.view.viser_scene
from c2rviz.app.config import load_settings
from c2rviz.ini import find_ini
from c2rviz.app.members import members
from c2rviz.robot.visuals import load_link_geometry
flags = {"robot_flag": False, "port_flag": False, "urdf_flag": False, "motion_flags": ()}
robots, _ = members(load_settings(find_ini(None), flags))
links = load_link_geometry(robots[0].robot.source)
assert sum(len(g.visual) for g in links.values()) > 5, links
from c2rviz.view.markers import marker_mesh
print("marker faces:", len(marker_mesh("arrow")[1]))
heavy = ("trimesh", "scipy", "rosbags", "yourdfpy", "networkx")
print("loaded:", ",".join(m for m in heavy if m in sys.modules) or "none")
"""


def test_the_start_loads_neither_trimesh_nor_scipy_nor_rosbags():
    """What the default start imports and builds (the default robot is drawn from boxes and
    cylinders) and a marker need none of them: trimesh comes with the first mesh file,
    scipy with the first IK solve, rosbags with the first recording (most of a second of
    a start)."""
    done = subprocess.run(
        [sys.executable, "-c", START_RUN], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "loaded: none" in done.stdout, done.stdout
    assert re.search(r"marker faces: [1-9]\d*", done.stdout), done.stdout


def test_the_import_contracts_hold():
    """import-linter's contracts (pyproject.toml): the layers, what the clients and the
    protocol may import, and no import cycle at any depth (TYPE_CHECKING imports count)."""
    linter = os.path.join(os.path.dirname(sys.executable), "lint-imports")
    done = subprocess.run(
        [linter, "--no-cache"], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 broken" in done.stdout or "Contracts: 3 kept, 0 broken" in done.stdout, done.stdout
