"""``grip`` through the real server: at once, travelling on the clock, asked, refused."""

from __future__ import annotations

import numpy as np
import pytest
from support import Client, ServerThread, load_robot

from c2rviz.protocol import replies
from c2rviz.session import ServerLimits
from c2rviz.world.virtual_clock import VirtualClock


def test_grip_at_once_and_asked(start_server, connect) -> None:
    server = start_server("fanuc_lrmate200id")
    client = connect(server)
    assert client.ask("grip") == "ok 0"  # the fingers start where the URDF's zero puts them
    assert client.ask("grip 1") == "ok"
    assert client.ask("grip") == "ok 1"
    assert client.ask("grip 0.25") == "ok"
    assert client.ask("grip") == "ok 0.25"
    assert server.call(lambda: server.world.state().opening) == 0.25
    assert [o for o, _ in server.scene.openings] == [1.0, 0.25]
    assert client.ask("where").startswith("ok")  # the chain is untouched


def test_grip_travels_with_motion_on_and_replies_on_arrival(connect) -> None:
    """On the virtual clock: the stroke's frames are stamped when they were due, not when a
    busy machine's loop woke (on the real clock a late first frame shortened the span)."""
    server = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    server.start()
    try:
        client = Client(server.host, server.port, timeout=30.0)  # a hang guard, not a timing
        assert client.ask("motion on") == "ok"
        assert client.ask("grip 1") == "ok"  # after 0.3 s of the world's clock
        openings = np.array(server.call(lambda: list(server.scene.openings)))
        values, times = openings[:, 0], openings[:, 1]
        assert values[-1] == 1.0 and len(values) > 3
        assert np.all(np.diff(values) >= 0) and np.all(np.diff(times) > 0)
        assert times[-1] - times[0] == pytest.approx(0.3, abs=0.02)  # the full stroke
        assert client.ask("grip") == "ok 1"
        client.close()
    finally:
        server.stop()


def test_a_new_grip_takes_over_and_the_waiting_one_hears_it(start_server, connect) -> None:
    server = start_server("fanuc_lrmate200id")
    first, second = connect(server), connect(server)
    assert first.ask("motion on") == "ok"
    first.send("grip 1\n")
    _wait_until(server, lambda: len(server.scene.openings) > 0)
    assert second.ask("grip 0") == "ok"  # motion off: at once
    assert first.read_line().startswith("error: preempted by tcp 127.0.0.1:")
    assert second.ask("grip") == "ok 0"


def test_a_robot_without_a_gripper_refuses(server: ServerThread, connect) -> None:
    client = connect(server)
    for line in ("grip", "grip 1"):
        reply = client.ask(line)
        assert reply.startswith("error: no gripper: motoman_sia20d has none"), reply
    assert client.ask("grip 2") == replies.error("grip: 2 is outside 0..1 (usage: grip [S])")


def _wait_until(server: ServerThread, condition) -> None:
    for _ in range(20_000):
        if server.call(condition):
            return
    raise AssertionError("never happened")


def test_a_grip_that_travels_answers_on_virtual_time(connect) -> None:
    """Issue 39, fault 13: the reply waited on a future the virtual clock did not know, so
    the client held the clock while it waited and time never reached the arrival."""
    server = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    server.start()
    try:
        client = Client(server.host, server.port, timeout=30.0)  # a hang guard, not a timing
        assert client.ask("motion on") == "ok"
        assert client.ask("grip 0") == "ok"  # already there: at once
        assert client.ask("grip 1") == "ok"  # the full stroke, on the clock
        assert server.call(server.world.clock.now) == pytest.approx(0.3)
        assert client.ask("grip") == "ok 1"
        client.close()
    finally:
        server.stop()
