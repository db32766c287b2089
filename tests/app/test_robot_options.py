"""What the ini gives a robot: its tool, motion limits and workcell objects (mesh too)."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh
from support import ROOT, Client, program_server

from c2rviz.app.cli import main

INI = """
[options]
robot = motoman_sia20d

[motoman_sia20d]
base = base_link
eelink = link_t
urdf = {root}/robots/motoman_sia20d/robot.urdf
tool = 0,0,0.1,0,0,0
max_velocity = 1.5
max_jerk = 20,20,20,20,20,20,30

[objects]
table = box 1.2,0.8,0.05 0.6,0,-0.03,0,0,0 0.6,0.5,0.3,0.8
post = cylinder 0.05,0.6 0,0.8,0.85,0,0,90
fixture = mesh part.stl 0,-0.8,0.85,0,0,0 2,2,2
"""


@pytest.fixture
def ini(tmp_path: Path) -> Path:
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(tmp_path / "part.stl")
    path = tmp_path / "cmdinterpreter.ini"
    path.write_text(INI.format(root=ROOT))
    return path


def test_the_ini_gives_the_robot_its_tool_limits_and_objects(ini: Path):
    with program_server(ini) as server:
        client = Client("127.0.0.1", server.port)
        try:
            assert client.ask("tool") == "ok 0,0,0.1,0,0,0"
            assert client.ask("pose").startswith("ok 0,0,1.6,")  # link_t at 1.5 m, plus the tool
            first = client.ask("limits all")[3:].split(",")
            assert " v=1.5 a=3 j=20" in first[0] and first[6].endswith(" j=30")
            assert client.ask("objects") == "ok table,post,fixture"
            client.ask("degrees")
            client.ask("j 90,60,0,0,0,0,0")  # the wrist into the post
            assert "~post" in client.ask("collisions")
            client.ask("j -90,60,0,0,0,0,0")  # ... and the other way, into the mesh
            assert "~fixture" in client.ask("collisions")
            assert client.ask("quit") == "ok"
            assert server.quit_requested.wait(60)  # quit ends the program
        finally:
            client.close()


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("tool = 0,0,0.1,0,0,0", "tool = 0,0,0.1", "[motoman_sia20d] tool = '0,0,0.1' must be 6"),
        ("max_velocity = 1.5", "max_velocity = -1", "[motoman_sia20d] max_velocity: joint 0"),
        ("max_jerk = 20,20,20,20,20,20,30", "max_jerk = 1,2", "[motoman_sia20d] max_jerk"),
        ("table = box 1.2,0.8,0.05", "table = box -1,0.8,0.05", "size"),
        ("post = cylinder", "post = cone", "cone"),
        ("fixture = mesh part.stl", "fixture = mesh missing.stl", "missing.stl"),
    ],
    ids=["tool-three", "velocity-negative", "jerk-two", "box-negative", "cone", "no-mesh"],
)
def test_bad_ini_furniture_exits_2_naming_it(
    ini: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, message: str
):
    ini.write_text(ini.read_text().replace(old, new))
    assert main(["--config", str(ini), "--no-viewer", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("c2rviz: ") and message in err and err.count("\n") == 1, err


def test_flags_override_the_ini_motion_limits(ini: Path, c2rviz_process):
    proc = c2rviz_process("--config", str(ini), "--no-viewer", "--max-velocity", "0.5")
    client = Client("127.0.0.1", proc.port)
    try:
        assert " v=0.5 a=1 j=20" in client.ask("limits all")[3:].split(",")[0]
    finally:
        client.close()
