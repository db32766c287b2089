"""Tests of the CRCL kitting program ``kit.xml``: a c2rviz server per test with the cell of
``kitting.ini`` (the fanuc, a table, a tray, three parts) and its CRCL door, on virtual
time; ``c2rviz-play`` runs the program against it, and the outcome is checked where the
parts ended (``assert_goals_met``, ``assert_part_at``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from c2rviz.clients.player import main as play
from c2rviz.testing import assert_goals_met, assert_part_at

HERE = Path(__file__).parent
KIT = HERE / "kit.xml"
"""The CRCL program: the three parts into the tray."""
SLOTS = {
    "p1": (0.40, -0.2, 0.225, 0.0, 0.0, 0.0),
    "p2": (0.45, -0.2, 0.225, 0.0, 0.0, 0.0),
    "p3": (0.50, -0.2, 0.225, 0.0, 0.0, 0.0),
}
"""The kit: where each part should end, on the tray [m, rad] (its goal)."""
START = {
    "p1": (0.40, 0.2, 0.215, 0.0, 0.0, 0.0),
    "p2": (0.45, 0.2, 0.215, 0.0, 0.0, 0.0),
    "p3": (0.50, 0.2, 0.215, 0.0, 0.0, 0.0),
}
"""Where kitting.ini puts the parts, on the table [m, rad]."""

pytestmark = pytest.mark.c2rviz(ini=str(HERE / "kitting.ini"), clock="virtual", crcl=True)


@pytest.fixture
def crcl_port(c2rviz_server) -> int:
    """The server's CRCL door (``crcl=True``: opened alone, on a free port)."""
    return c2rviz_server.crcl_port


def run_kit(server, port: int, program: Path = KIT) -> int:
    """``c2rviz-play PROGRAM --port PORT --quiet``; the test's client idle meanwhile."""
    with server.idle_clients():  # virtual time waits for no idle client
        return play([str(program), "--port", str(port), "--quiet"])


def test_the_program_puts_every_part_in_the_kit(crcl_port, c2rviz, c2rviz_server, capsys):
    for name, slot in SLOTS.items():
        c2rviz.goal(name, slot)
    assert c2rviz.score().met == 0
    assert run_kit(c2rviz_server, crcl_port) == 0, capsys.readouterr()
    assert "28 CRCL commands, all done" in capsys.readouterr().out
    assert_goals_met(c2rviz)
    for name, slot in SLOTS.items():
        assert_part_at(c2rviz, name, slot, tol=0.001, tol_angle=0.01)
        assert c2rviz.part(name).state == "resting on tray"
    assert c2rviz.grip() == 1.0  # open at the end


def test_the_gripper_grasps_each_part_on_the_way(crcl_port, c2rviz, c2rviz_server, capsys):
    with c2rviz.watch() as stream:
        assert run_kit(c2rviz_server, crcl_port) == 0, capsys.readouterr()
        c2rviz.sleep(0)  # its reply comes after every event so far
        events = []
        for record in stream:
            kind = getattr(record, "kind", None)
            if kind in ("grasped", "released"):
                events.append(f"{kind} {record.detail}")
            if len(events) == 6:
                break
    assert events == [f"{e} p{i}" for i in (1, 2, 3) for e in ("grasped", "released")]


def test_a_part_out_of_place_is_left_and_the_score_says_so(
    crcl_port, c2rviz, c2rviz_server, capsys
):
    c2rviz.remove_part("p2")
    c2rviz.add_part("p2", "box", (0.03, 0.03, 0.03), (0.45, 0.3, 0.215, 0, 0, 0))  # 10 cm off
    for name, slot in SLOTS.items():
        c2rviz.goal(name, slot)
    assert run_kit(c2rviz_server, crcl_port) == 0, capsys.readouterr()  # the fingers miss it
    assert c2rviz.score().met == 2
    assert_part_at(c2rviz, "p2", (0.45, 0.3, 0.215, 0, 0, 0))  # where it was
    with pytest.raises(AssertionError, match="p2"):
        assert_goals_met(c2rviz)
