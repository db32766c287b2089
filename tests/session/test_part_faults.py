"""The part faults through the real server, on virtual time: ``fault drop [PART]`` (now,
and scheduled mid-carry), ``fault slip P`` (1 always, 0 never, 0.5 the same with the same
seed), a parallel gripper and a vacuum cup alike, and bad input refused with nothing changed.

The scene is tests/session/test_part_verbs.py's: the bundled fanuc pointing down at a
tall part standing on a table, the jaws around it.
"""

from __future__ import annotations

import math

import pytest
from support import Client

from c2rviz.testing.server import TestServer

PICK = "0,0.3,-0.3,0,-0.9707963,0"
LIFT = "0,0,0,0,-1.5707963,0"
OFF_TABLE = "1.5707963,0,0,0,-1.5707963,0"
TABLE_TOP = 0.179
TABLE = f"object table box 0.4,0.6,0.05 0.45,0,{TABLE_TOP - 0.025:.4f},0,0,0"
TALL = 0.17
PART = f"part p1 box 0.03,0.03,{TALL} 0.4438,0,{TABLE_TOP + TALL / 2:.4f},0,0,0"


def _server(seed: int = 3, motion: str = "off") -> TestServer:
    return TestServer(
        {"robot": "fanuc_lrmate200id", "clock": "virtual", "plan_seed": seed, "motion": motion}
    ).start()


@pytest.fixture
def fanuc():
    server = _server()
    client = Client(server.host, server.port)
    try:
        yield server, client
    finally:
        client.close()
        server.stop()


def _at_pick(client: Client) -> None:
    for line in ("grip 1", TABLE, f"joints {PICK}", PART):
        assert client.ask(line) == "ok", line


def ask(client: Client, line: str, seen: list[str]) -> str:
    """Send ``line`` to a watching client; its reply, the stream's lines kept in ``seen``."""
    client.send(line + "\n")
    while True:
        got = client.read_line()
        assert got, "the server closed the connection"
        if got.startswith(("ok", "error")):
            return got
        seen.append(got)


def _pose(reply: str) -> list[float]:
    return [float(v) for v in reply.split()[1].split(",")]


def test_drop_now_releases_the_part_by_the_release_rule_and_watch_tells_it(fanuc):
    server, client = fanuc
    watcher = Client(server.host, server.port)
    try:
        assert watcher.ask("watch 1") == "ok"
        _at_pick(client)
        assert client.ask("grip 0").startswith("ok 0.")
        assert client.ask(f"joints {LIFT}") == "ok"
        assert client.ask("fault drop") == "ok"
        assert client.ask("part p1").endswith(" free")  # falling on the world's clock
        assert client.ask("sleep 1") == "ok"
        reply = client.ask("part p1")
        assert reply.endswith(" resting on table"), reply
        assert _pose(reply)[2] == pytest.approx(TABLE_TOP + TALL / 2, abs=1e-3)
        assert client.ask("faults") == "ok none"  # it happened once: nothing lasts
        seen: list[str] = []
        assert ask(watcher, "watch 1", seen) == "ok"
        events = [line for line in seen if line.startswith("event ") and "collision" not in line]
        assert events == [
            "event grasped p1",
            "event fault drop",
            "event released p1",
            "event resting p1 on table",
        ]
    finally:
        watcher.close()


def test_drop_part_releases_that_part_and_one_not_held_is_refused(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask("part p2 sphere 0.02 1,1,0.02") == "ok"
    refused = "error: fault: fanuc_lrmate200id does not hold {} (it holds {}) (usage: fault"
    assert client.ask("fault drop p1").startswith(refused.format("'p1'", "nothing"))
    assert client.ask("grip 0").startswith("ok 0.")
    assert client.ask("fault drop p2").startswith(refused.format("'p2'", "p1"))
    assert client.ask("fault drop p9").startswith(refused.format("'p9'", "p1"))
    assert client.ask("part p1").endswith(" held")  # nothing changed
    assert client.ask("fault drop p1") == "ok"
    assert client.ask("part p1").endswith(" resting on table")


def test_drop_with_nothing_held_is_a_no_op(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask("fault drop") == "ok"
    assert client.ask("part p1").endswith(" resting on table")
    assert client.ask("grip 0").startswith("ok 0.")  # the gripper works as before


def _carry_and_drop(when: str) -> tuple[str, list[float]]:
    """Pick p1, lift it, schedule a drop ``when`` (``after S``) and carry it off the
    table; the part's last reply and the carry's start pose."""
    server = _server(motion="on")
    client = Client(server.host, server.port)
    try:
        _at_pick(client)
        assert client.ask("grip 0").startswith("ok 0.")
        assert client.ask(f"joints {LIFT}") == "ok"
        lifted = _pose(client.ask("part p1"))
        assert client.ask(f"fault {when} drop p1") == "ok"
        assert client.ask(f"joints {OFF_TABLE}") == "ok"
        assert client.ask("sleep 3") == "ok"
        return client.ask("part p1"), lifted
    finally:
        client.close()
        server.stop()


def test_a_drop_scheduled_mid_carry_lands_below_where_it_was_and_replays_exactly():
    reply, lifted = _carry_and_drop("after 0.3")
    assert reply.endswith((" resting on table", " resting on floor")), reply
    x, y, z, *_ = _pose(reply)
    # joint 0 swings the part on a circle about the base: it fell straight down from it,
    # part of the way round (neither where the carry began nor where it ends)
    assert math.hypot(x, y) == pytest.approx(math.hypot(*lifted[:2]), abs=1e-3)
    angle = math.atan2(y, x)
    assert 0.01 < angle < math.pi / 2 - 0.01
    assert z in (pytest.approx(TABLE_TOP + TALL / 2, abs=1e-3), pytest.approx(TALL / 2, abs=1e-3))
    assert _carry_and_drop("after 0.3")[0] == reply  # the same time, the same pose


def _slips(seed: int, p: str, tries: int = 8) -> list[str]:
    """``grip 0`` on p1 ``tries`` times with ``fault slip p``: each reply."""
    server = _server(seed)
    client = Client(server.host, server.port)
    try:
        _at_pick(client)
        assert client.ask(f"fault slip {p}") == "ok"
        out = []
        for _ in range(tries):
            out.append(client.ask("grip 0"))
            held = client.ask("part p1").endswith(" held")
            assert held == (out[-1] != "ok"), out[-1]
            assert client.ask("grip 1") == "ok"
        return out
    finally:
        client.close()
        server.stop()


def test_slip_1_always_fails_0_never_and_0_5_the_same_with_the_same_seed():
    assert _slips(3, "1") == ["ok"] * 8  # the fingers close on nothing, as on a miss
    assert all(reply.startswith("ok 0.") for reply in _slips(3, "0"))
    first = _slips(5, "0.5", 16)
    assert first == _slips(5, "0.5", 16)
    assert "ok" in first and any(r.startswith("ok 0.") for r in first)


def test_slip_is_listed_cleared_and_told(fanuc):
    server, client = fanuc
    watcher = Client(server.host, server.port)
    try:
        assert watcher.ask("watch 1") == "ok"
        _at_pick(client)
        assert client.ask("fault slip 1") == "ok"
        assert client.ask("faults").startswith("ok slip 1 since ")
        assert client.ask("grip 0") == "ok"
        assert client.ask("grip 1") == "ok"
        assert client.ask("fault clear slip") == "ok"
        assert client.ask("faults") == "ok none"
        assert client.ask("grip 0").startswith("ok 0.")
        assert client.ask("sleep 1") == "ok"
        seen: list[str] = []
        assert ask(watcher, "watch 1", seen) == "ok"
        events = [line for line in seen if line.startswith("event ") and "collision" not in line]
        assert events == [
            "event fault slip 1",
            "event slipped p1",
            "event cleared slip 1",
            "event grasped p1",
        ]
    finally:
        watcher.close()


@pytest.mark.parametrize(
    ("line", "problem"),
    [
        ("fault slip 2", "slip P 2 is outside 0..1 (a chance per grasp)"),
        ("fault slip -1", "slip P -1 is outside 0..1 (a chance per grasp)"),
        ("fault slip", "slip needs one P (a chance per grasp, 0..1)"),
        ("fault slip 0.1,0.2", "slip needs one P (a chance per grasp, 0..1)"),
        ("fault drop p1 p2", "drop takes at most one PART"),
    ],
)
def test_bad_part_faults_are_refused_and_change_nothing(fanuc, line, problem):
    _, client = fanuc
    assert client.ask(line) == f"error: fault: {problem} (usage: fault [at T|after S] KIND " + (
        "[ARGS] | clear [KIND|all])"
    )
    assert client.ask("faults") == "ok none"


@pytest.fixture
def vacuum():
    from support import ROBOTS, ROOT, ServerLimits, ServerThread

    from c2rviz.robot.model import Robot
    from c2rviz.world.part_rules import make_vacuum
    from c2rviz.world.virtual_clock import VirtualClock

    path, base, eelink = ROBOTS["motoman_sia20d"]
    robot = Robot.from_urdf(ROOT / path, base, eelink)  # its own: the cached one stays bare
    robot.gripper = make_vacuum(robot.eelink)
    server = ServerThread(robot, ServerLimits(), clock=VirtualClock()).start()
    client = Client(server.host, server.port)
    try:
        yield server, client
    finally:
        client.close()
        server.stop()


def test_a_vacuum_grasp_slips_and_a_sucked_part_drops(vacuum):
    _, client = vacuum
    x, y, z = [float(v) for v in client.ask("pose")[3:].split(",")[:3]]
    assert client.ask(f"part b sphere 0.02 {x},{y},{z - 0.02}") == "ok"
    assert client.ask("fault slip 1") == "ok"
    assert client.ask("grip 0") == "ok"  # not `ok held`: suction on, nothing taken
    assert client.ask("part b").endswith(" free")  # where it was put, under the cup
    assert client.ask("grip 1") == "ok"
    assert client.ask("fault clear slip") == "ok"
    assert client.ask("grip 0") == "ok held"
    assert client.ask("fault drop b") == "ok"
    assert client.ask("part b").endswith(" free")  # falling
    assert client.ask("sleep 3") == "ok"
    assert client.ask("part b").endswith(" resting on floor")
