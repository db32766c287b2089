"""What the page hears besides joints: refusals (with a guarded move's target), and the
``ghost`` verb — through the real server, from the observer's side (``RecordingScene``)."""

from __future__ import annotations

import math

import numpy as np
from support import ServerThread

from c2rviz.world.observer import Observer

BOX = "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0"  # beside the motoman, at +y
REACH = "0,60,0,0,0,0,0"  # degrees: the arm held out along +x
INTO = "90,60,0,0,0,0,0"  # ... swung round to +y: into the box


def test_a_refusal_reaches_the_observers_with_its_line_and_message(server: ServerThread, connect):
    client = connect(server)
    assert client.ask("move 9 1").startswith("error: joint index 9 out of range")
    robot, line, message = server.call(lambda: server.scene.errors[-1])
    assert (robot, line) == ("motoman_sia20d", "move 9 1")
    assert message.startswith("joint index 9 out of range")


def test_a_guarded_target_that_collides_is_told_with_its_target(server: ServerThread, connect):
    client = connect(server)
    for line in ("degrees", BOX, f"j {REACH}", "guard on"):
        assert client.ask(line) == "ok", line
    reply = client.ask(f"j {INTO}")
    assert "would hit table" in reply
    error = server.call(lambda: server.scene.errors[-1])
    assert error[1] == f"j {INTO}" and "would hit table" in error[2]


def test_a_refusal_that_comes_with_the_reply_is_told_too(server: ServerThread, connect):
    """A guarded movel is refused after its line is planned (its reply waits): the world
    hears of it when the reply comes, with the target the line ended at."""
    targets: list[tuple[float, ...] | None] = []

    class Targets(Observer):
        def on_refused(self, robot, source, line, error):
            targets.append(getattr(error, "target", None))

    server.call(lambda: server.world.add_observers([Targets()]))
    client = connect(server)
    for line in ("degrees", BOX, "j 70,60,0,0,0,0,0"):
        assert client.ask(line) == "ok", line
    assert client.ask("j 110,60,0,0,0,0,0") == "ok"
    right = client.ask("pose")[3:]
    assert client.ask("j 70,60,0,0,0,0,0") == "ok"
    assert client.ask("guard on") == "ok"
    reply = client.ask(f"movel {right}")
    assert "would hit table" in reply, reply
    target = server.call(lambda: targets[-1])
    assert target is not None and len(target) == 7
    # The line's end: the tool where `pose` said, joint_s near 110 degrees.
    assert math.isclose(math.degrees(target[0]), 110.0, abs_tol=1.0)


def test_a_preempted_move_is_not_a_refusal(server: ServerThread, connect):
    mover, other = connect(server), connect(server)
    for line in ("degrees", "motion on", "speed 5"):
        assert mover.ask(line) == "ok"
    mover.send("j 90,0,0,0,0,0,0\n")
    for _ in range(10_000):
        if other.ask("status").startswith("ok moving"):
            break
    assert other.ask("j 0,0,0,0,0,0,0") == "ok"
    assert mover.read_line().startswith("error: preempted")
    assert server.call(lambda: list(server.scene.errors)) == []


def test_ghost_is_per_robot_on_by_default_and_told_to_the_observers(server: ServerThread, connect):
    client = connect(server)
    assert client.ask("ghost") == "ok on"
    assert client.ask("ghost off") == "ok"
    assert client.ask("ghost") == "ok off"
    assert connect(server).ask("ghost") == "ok off"  # the robot's, not the connection's
    assert client.ask("ghost sideways").startswith("error: ghost: unknown action 'sideways'")
    assert client.ask("ghost on") == "ok"
    assert server.call(lambda: server.scene.ghosts) == [
        ("motoman_sia20d", False),
        ("motoman_sia20d", True),
    ]
    assert np.isclose(server.q, 0.0).all()  # nothing moved
