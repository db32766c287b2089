"""``c2rviz-play program.xml``: a CRCL program run over the CRCL door, command by command."""

from __future__ import annotations

import socket
from pathlib import Path

import numpy as np
import pytest
from crcl_support import CrclServerThread, pose, schema
from lxml import etree

from c2rviz.clients import player

HEAD = '<?xml version="1.0" encoding="UTF-8"?>\n'
XSI = 'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'


def program(*middle: str, init: int = 1, end: int = 99) -> str:
    """A CRCLProgram as NIST's sample programs are laid out."""
    lines = [
        f"{HEAD}<CRCLProgram {XSI}>",
        f"  <InitCanon>\n    <CommandID>{init}</CommandID>\n  </InitCanon>",
        *middle,
        f"  <EndCanon>\n    <CommandID>{end}</CommandID>\n  </EndCanon>",
        "</CRCLProgram>\n",
    ]
    return "\n".join(lines)


def middle(kind: str, command_id: int, body: str = "") -> str:
    return (
        f'  <MiddleCommand xsi:type="{kind}Type">\n    <CommandID>{command_id}</CommandID>\n'
        f"{body}\n  </MiddleCommand>"
    )


def move(command_id: int, point: tuple[float, float, float]) -> str:
    body = "    <MoveStraight>false</MoveStraight>\n" + pose("EndPosition", point)
    return middle("MoveTo", command_id, body)


GOOD = program(
    middle("SetLengthUnits", 2, "    <UnitName>millimeter</UnitName>"),
    move(3, (500.0, 0.0, 800.0)),
    middle("Message", 4, "    <Message>at the first point</Message>"),
    move(5, (600.0, 200.0, 600.0)),
)


def write(tmp_path: Path, text: str, name: str = "demo.xml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    checker = schema("CRCLProgramInstance.xsd")
    assert checker is None or checker.validate(etree.fromstring(text.encode()))
    return path


def play(server: CrclServerThread, path: Path, *extra: str) -> int:
    argv = [str(path), "--host", "127.0.0.1", "--port", str(server.crcl_port), *extra]
    return player.main(argv)


def test_a_program_runs_command_by_command(crcl_server, tmp_path, capsys) -> None:
    path = write(tmp_path, GOOD)
    assert play(crcl_server, path) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "[0/5] InitCanonType (CommandID 1): done"
    assert out[3] == "[3/5] MessageType (CommandID 4): done"
    assert out[5] == "[5/5] EndCanonType (CommandID 99): done"
    assert out[6].startswith("demo.xml: 6 CRCL commands, all done, in ")
    tool = crcl_server.call(lambda: crcl_server.world.ee_pose().translation.copy())
    np.testing.assert_allclose(tool, (0.6, 0.2, 0.6), atol=1e-6)
    logged = crcl_server.call(lambda: list(crcl_server.scene.commands))
    assert "MessageType (CommandID 4): at the first point" in logged


def test_the_first_error_stops_the_run_with_its_index(crcl_server, tmp_path, capsys) -> None:
    bad = program(
        move(2, (0.5, 0.0, 0.8)),
        move(3, (3.0, 0.0, 0.0)),
        middle("Message", 4, "    <Message>never</Message>"),
    )
    assert play(crcl_server, write(tmp_path, bad, "bad.xml")) == 1
    captured = capsys.readouterr()
    assert "[2/4] MoveToType (CommandID 3): error" in captured.out
    assert captured.err.startswith(
        "bad.xml: command 2 (MoveToType, CommandID 3): MoveToType (CommandID 3): pose unreachable"
    )
    logged = crcl_server.call(lambda: list(crcl_server.scene.commands))
    assert not any("never" in line for line in logged)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (GOOD.replace("<InitCanon>", "<Init>").replace("</InitCanon>", "</Init>"), "InitCanon"),
        (GOOD.replace("MoveToType", "FlyToType", 1), "unknown xsi:type 'FlyToType'"),
        (GOOD.replace("<Z>800.0</Z>", "<Z>NaN</Z>"), "NaN is not allowed"),
        (GOOD[:200], "malformed XML"),
    ],
    ids=["no-init-canon", "unknown-type", "nan", "cut-short"],
)
def test_a_bad_program_sends_nothing(crcl_server, tmp_path, capsys, text: str, words: str) -> None:
    path = tmp_path / "broken.xml"
    path.write_text(text)
    assert play(crcl_server, path) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"c2rviz-play: {path}: ") and words in err, err
    assert crcl_server.call(lambda: list(crcl_server.scene.commands)) == []


def test_check_only_reads_the_program(tmp_path, capsys) -> None:
    assert player.main([str(write(tmp_path, GOOD)), "--check"]) == 0
    assert capsys.readouterr().out == "demo.xml: 6 CRCL commands, all check\n"


def test_quiet_shows_the_summary_alone(crcl_server, tmp_path, capsys) -> None:
    assert play(crcl_server, write(tmp_path, GOOD), "--quiet") == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 1 and out[0].startswith("demo.xml: 6 CRCL commands, all done, in ")
    bad = program(move(2, (3.0, 0.0, 0.0)))
    assert play(crcl_server, write(tmp_path, bad, "bad.xml"), "-q") == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("bad.xml: command 1 (MoveToType, CommandID 2): ")


@pytest.mark.parametrize(
    ("x_axis", "z_axis"),
    [((1e300, 0, 0), (0, 0, -1)), ((1, 0, 0), (0, 0, -1e300)), ((1, 0, 0), (0, 1e308, 0))],
    ids=["x-i", "z-k", "z-j"],
)
def test_check_of_a_huge_axis_is_one_line_and_exit_2(tmp_path, capsys, x_axis, z_axis) -> None:
    """Issue 39, fault 2: `--check` printed a traceback and exited 1."""
    body = "    <MoveStraight>false</MoveStraight>\n" + pose(
        "EndPosition", (500.0, 0.0, 800.0), x_axis, z_axis
    )
    path = tmp_path / "huge.xml"
    path.write_text(program(middle("MoveTo", 2, body)))
    assert player.main([str(path), "--check"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err
    assert captured.err.startswith(f"c2rviz-play: {path}: "), captured.err


def test_no_server_is_exit_1(tmp_path, capsys) -> None:
    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    argv = [str(write(tmp_path, GOOD)), "--port", str(port), "--timeout", "0.2"]
    assert player.main(argv) == 1
    assert "no c2rviz CRCL door at 127.0.0.1:" in capsys.readouterr().err


def test_the_bundled_pick_and_place_plays_all_done(start_crcl, capsys) -> None:
    """commands/crcl_fanuc_pick.xml: the fanuc picks with its gripper and places."""
    server = start_crcl("fanuc_lrmate200id")
    assert play(server, Path("crcl_fanuc_pick.xml")) == 0, capsys.readouterr()
    out = capsys.readouterr().out
    assert "[ 5/13] SetEndEffectorType (CommandID 6): done" in out
    assert out.splitlines()[-1].startswith("crcl_fanuc_pick.xml: 14 CRCL commands, all done")
    tool = server.call(lambda: server.world.ee_pose().translation.copy())
    np.testing.assert_allclose(tool, (0.4, 0.2, 0.4), atol=1e-6)
    assert server.opening() == 1.0
    openings = [o for o, _ in server.call(lambda: list(server.scene.openings))]
    assert 0.3 in openings  # closed on the part between
