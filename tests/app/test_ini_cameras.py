"""The ini's ``[cameras]``: cameras in the world at the start, and bad ones refused."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import ROOT, Client, program_server

from c2rviz.app.cli import main

INI = """
[options]
robot = fanuc_lrmate200id

[fanuc_lrmate200id]
base = base_link
eelink = link_6
urdf = {root}/robots/fanuc_lrmate200id/robot.urdf

[parts]
p1 = box 0.03,0.03,0.06 0.45,0,0.03,0,0,0 type=block

[cameras]
top = 0.45,0,1.2,0,90,0
side = 0.45,-1,0.03,0,0,90  50,40,2.5  rate=5  noise=0,0
"""


@pytest.fixture
def ini(tmp_path: Path) -> Path:
    path = tmp_path / "cmdinterpreter.ini"
    path.write_text(INI.format(root=ROOT))
    return path


def test_the_ini_puts_its_cameras_in_the_world(ini: Path):
    with program_server(ini) as server:
        client = Client("127.0.0.1", server.port)
        try:
            assert client.ask("degrees") == "ok"
            assert client.ask("cameras") == (
                "ok top:0.45,0,1.2,0,90,0:60,45,2:10;side:0.45,-1,0.03,0,0,90:50,40,2.5:5"
            )
            assert client.ask("camera top") == "ok p1:block:1.17,0,0,0,-90,0"
            assert client.ask("camera side") == "ok p1:block:1,0,0,0,0,-90"
            assert client.ask("quit") == "ok"
            assert server.quit_requested.wait(60)  # quit ends the program
        finally:
            client.close()


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("50,40,2.5", "0,40,2.5", "[cameras] side: h_fov = 0 deg must be above 0"),
        ("50,40,2.5", "50,180,2.5", "v_fov = 180 deg must be above 0 and below 180"),
        ("50,40,2.5", "50,40,-1", "range = -1 m must be above 0"),
        ("rate=5", "rate=1e308", "rate 1e+308 is outside 0..100 Hz"),
        ("rate=5", "speed=5", "'speed=5' is not h_fov,v_fov,range"),
        ("0.45,0,1.2,0,90,0", "0.45,0,1.2", "must be 6 numbers"),
    ],
    ids=["zero-fov", "fov-180", "negative-range", "huge-rate", "unknown-option", "short-pose"],
)
def test_bad_ini_cameras_exit_2_naming_them(
    ini: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, message: str
):
    ini.write_text(ini.read_text().replace(old, new))
    assert main(["--config", str(ini), "--no-viewer", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("c2rviz: ") and message in err and err.count("\n") == 1, err
