"""The ini's ``[parts]``: parts around the first robot at the start, and bad ones refused."""

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

[objects]
table = box 0.4,0.6,0.05 0.45,0,0.175,0,0,0

[parts]
p1 = box 0.03,0.03,0.06 0.45,0,0.23,0,0,90 type=block color=1,0.5,0
ball = sphere 0.02 0.45,0.2,0.22,0,0,0
"""


@pytest.fixture
def ini(tmp_path: Path) -> Path:
    path = tmp_path / "cmdinterpreter.ini"
    path.write_text(INI.format(root=ROOT))
    return path


def test_the_ini_puts_its_parts_in_the_world(ini: Path):
    with program_server(ini) as server:
        client = Client("127.0.0.1", server.port)
        try:
            client.ask("degrees")
            assert client.ask("parts") == (
                "ok p1:0.45,0,0.23,0,0,90:resting on table;"
                "ball:0.45,0.2,0.22,0,0,0:resting on table"
            )
            assert client.ask("quit") == "ok"
            assert server.quit_requested.wait(60)  # quit ends the program
        finally:
            client.close()


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("0.45,0,0.23,0,0,90", "0.45,0,0.17,0,0,90", "[parts] p1: part 'p1' would be"),
        ("type=block", "hue=3", "'hue=3' is not type=TYPE"),
        ("sphere 0.02", "sphere 1e308", "outside 0.001..2 m"),
        ("ball = sphere", "table = sphere", "already an object's"),
    ],
    ids=["inside", "option", "huge", "object-name"],
)
def test_bad_ini_parts_exit_2_naming_them(
    ini: Path, capsys: pytest.CaptureFixture[str], old: str, new: str, message: str
):
    ini.write_text(ini.read_text().replace(old, new))
    assert main(["--config", str(ini), "--no-viewer", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("c2rviz: ") and message in err and err.count("\n") == 1, err
