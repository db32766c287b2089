"""Motion through the real server: moves that take time, replies on arrival, preemption,
stop, follow and speed — judged from the frames the world published (their clock times)
and the order of replies, never from how long the test took."""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np
import pytest
from support import Client, ServerThread, load_robot

from c2rviz.motion.limits import motion_limits
from c2rviz.session import ServerLimits
from c2rviz.world.virtual_clock import VirtualClock

FAR = "90,45,0,-30,0,60,0"  # degrees, motoman_sia20d
OTHER = "-45,20,30,0,0,-30,0"
SLACK = 1.02  # finite differences of sampled positions, against the limits


@pytest.fixture
def open_client(server: ServerThread, connect) -> Callable[..., Client]:
    """Factory: ``client(mode=None, speed=None)``, a degrees client in that motion mode."""

    def open_client(mode: str | None = None, speed: int | None = None) -> Client:
        opened = connect(server)
        assert opened.ask("degrees") == "ok"
        for line in (f"motion {mode}" if mode else "", f"speed {speed}" if speed else ""):
            if line:
                assert opened.ask(line) == "ok"
        return opened

    return open_client


def wait_until_moving(client: Client) -> float:
    """Ask ``status`` until the arm moves; return the seconds left it reports."""
    for _ in range(10_000):
        reply = client.ask("status")
        if reply.startswith("ok moving"):
            return float(reply.split()[2])
    raise AssertionError("the arm never started moving")


def degrees(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split(",")])


def frames(server: ServerThread, since: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and joint values [rad] the world published, from entry ``since`` on."""
    times, joints = server.call(lambda: (list(server.scene.times), list(server.scene.joints)))
    return np.array(times[since:]), np.array(joints[since:])


def frame_count(server: ServerThread) -> int:
    return server.call(lambda: len(server.scene.joints))


def assert_within_limits(server: ServerThread, t: np.ndarray, q: np.ndarray, speed: float):
    """Between published frames no joint went faster than its limit x speed."""
    limits = np.array(motion_limits(server.robot).velocity) * speed
    dt = np.diff(t)
    keep = dt > 1e-6
    velocity = np.abs(np.diff(q, axis=0)[keep]) / dt[keep, None]
    assert (velocity <= limits * SLACK + 1e-9).all(), velocity.max(axis=0) / limits


@pytest.mark.wall_clock
def test_a_move_replies_on_arrival_and_where_tells_the_arm_as_it_is(server, open_client):
    mover = open_client("on", 25)
    watcher = open_client()
    start = frame_count(server)
    mover.send(f"j {FAR}\n")
    assert wait_until_moving(watcher) > 0
    target = degrees(FAR)
    moved = target != 0
    midway = degrees(watcher.ask("where")[3:])
    for _ in range(10_000):  # the first instants move less than where's 10 digits show
        if (midway[moved] != 0).all():
            break
        midway = degrees(watcher.ask("where")[3:])
    assert (np.abs(midway[moved]) < np.abs(target[moved])).all()
    assert (np.sign(midway[moved]) == np.sign(target[moved])).all()
    assert watcher.ask("target") == f"ok {FAR}"
    assert mover.read_line() == "ok"  # only now, at arrival
    assert mover.ask("where") == f"ok {FAR}"
    assert mover.ask("status") == "ok idle"
    t, q = frames(server, start)
    np.testing.assert_allclose(q[-1], np.radians(target), atol=1e-12)
    assert_within_limits(server, t, q, 0.25)
    # Every moving joint starts and arrives together (time-synchronized, within a frame).
    # A change is one above rounding, in proportion to the joint's travel: the joints
    # follow one profile scaled, so a frame 0.3 ms before arrival (a busy machine's loop
    # can publish one) moves the longest 1e-12 rad and the shortest less.
    travel = np.abs(np.radians(target))
    changes = np.abs(np.diff(q, axis=0)) > 1e-12 * travel / travel.max()
    firsts = [t[np.argmax(changes[:, j]) + 1] for j in np.flatnonzero(moved)]
    lasts = [t[len(changes) - np.argmax(changes[::-1, j])] for j in np.flatnonzero(moved)]
    assert max(firsts) - min(firsts) <= 0.02 and max(lasts) - min(lasts) <= 1e-9


@pytest.mark.wall_clock
def test_a_second_client_preempts_without_a_jump(server: ServerThread, open_client):
    first = open_client("on", 30)
    second = open_client("on", 100)
    start = frame_count(server)
    first.send(f"j {FAR}\n")
    wait_until_moving(second)
    assert second.ask(f"j {OTHER}") == "ok"
    assert re.fullmatch(r"error: preempted by tcp 127\.0\.0\.1:\d+", first.read_line())
    assert first.ask("where") == f"ok {OTHER}"
    t, q = frames(server, start)
    assert_within_limits(server, t, q, 1.0)  # no jump at the switch: position continuous
    # Nor a kink: the second divided difference of the frames is the acceleration at some
    # instant between them, so a velocity jump at the switch would show far past the limit.
    keep = np.concatenate([[True], np.diff(t) > 1e-3])
    t, q = t[keep], q[keep]
    velocity = np.diff(q, axis=0) / np.diff(t)[:, None]
    middles = (t[1:] + t[:-1]) / 2
    acceleration = np.abs(np.diff(velocity, axis=0)) / np.diff(middles)[:, None]
    limits = np.array(motion_limits(server.robot).acceleration)
    assert (acceleration <= limits * SLACK + 1e-6).all(), acceleration.max(axis=0) / limits
    np.testing.assert_allclose(q[-1], np.radians(degrees(OTHER)), atol=1e-12)


@pytest.mark.wall_clock
def test_stop_brings_the_arm_to_rest_and_tells_the_waiting_client(
    server: ServerThread, open_client
):
    mover = open_client("on", 30)
    stopper = open_client()
    start = frame_count(server)
    mover.send(f"j {FAR}\n")
    wait_until_moving(stopper)
    assert stopper.ask("stop") == "ok"  # the reply comes at rest
    assert stopper.ask("status") == "ok idle"
    assert re.fullmatch(r"error: motion stopped by tcp 127\.0\.0\.1:\d+", mover.read_line())
    rest = degrees(mover.ask("where")[3:])
    target = degrees(FAR)
    moved = target != 0
    assert (np.abs(rest[moved]) < np.abs(target[moved])).all()
    assert mover.ask("target") == mover.ask("where")  # at rest where it stopped
    t, q = frames(server, start)
    assert_within_limits(server, t, q, 0.3)
    assert stopper.ask("stop") == "ok"  # at rest already: at once


def test_follow_answers_at_once_lags_a_fast_target_and_ends_at_the_last(
    server: ServerThread, open_client
):
    streamer = open_client("follow", 100)
    start = frame_count(server)
    setpoints = [60.0 * math.sin(2 * math.pi * 2.0 * k / 100) for k in range(200)]
    lines = "".join(f"move 0 {v:.6f}\n" for v in setpoints)
    streamer.send(lines)  # 200 setpoints at once: each answered without waiting for the arm
    assert [streamer.read_line() for _ in setpoints] == ["ok"] * len(setpoints)
    assert streamer.ask("wait") == "ok"
    assert streamer.ask("where").startswith(f"ok {setpoints[-1]:.6g}"[:8])
    t, q = frames(server, start)
    assert_within_limits(server, t, q, 1.0)
    np.testing.assert_allclose(q[-1, 0], math.radians(setpoints[-1]), atol=1e-9)


def test_streamed_setpoints_lag_behind_a_target_faster_than_the_arm(connect) -> None:
    """On the virtual clock, so the target runs at 100 Hz of the server's clock exactly: on
    the real one each round trip a busy machine added slowed the sine down, and the arm
    could then follow it further than a 2 Hz sine allows."""
    server = ServerThread(load_robot(), ServerLimits(), clock=VirtualClock()).start()
    try:
        streamer = connect(server)  # one client: an idle second one would hold the clock
        for line in ("degrees", "motion follow", "speed 100"):
            assert streamer.ask(line) == "ok"
        start = frame_count(server)
        for k in range(200):  # 100 Hz on the server's own clock: 10 ms between setpoints
            setpoint = 60.0 * math.sin(2 * math.pi * 2.0 * k / 100)
            assert streamer.ask(f"move 0 {setpoint:.6f}") == "ok"
            assert streamer.ask("sleep 0.01") == "ok"
        assert streamer.ask("wait") == "ok"
        t, q = frames(server, start)
        assert t[-1] - t[0] >= 1.99 - 0.01  # two seconds of the clock: the whole stream
        assert_within_limits(server, t, q, 1.0)
        # A 2 Hz, 60 degree sine needs 13 rad/s; the arm (2.26 rad/s) never swings that far.
        assert np.abs(q[:, 0]).max() < math.radians(60.0) * 0.9
    finally:
        server.stop()


def test_speed_scales_the_duration_as_the_profile_predicts(server: ServerThread, open_client):
    client = open_client("follow", 100)
    assert client.ask("j 20,0,0,0,0,0,0") == "ok"
    fast = float(client.ask("status").split()[2])
    assert client.ask("wait") == "ok"
    assert client.ask("speed 10") == "ok"
    assert client.ask("j 0,0,0,0,0,0,0") == "ok"
    slow = float(client.ask("status").split()[2])
    assert client.ask("stop") == "ok"
    # At speed f the move from rest is the full-speed move played 1/f times slower.
    assert slow / fast == pytest.approx(10.0, rel=0.02)


@pytest.mark.parametrize("verb", ["home", "rand", "clear"])
def test_home_rand_and_clear_travel_too(server: ServerThread, open_client, verb: str):
    """On the virtual clock: the watcher, connected, holds time still while it sees the
    arm moving; once it leaves, the move's time passes at once and the reply comes."""
    mover = open_client("off")
    mover.ask(f"j {FAR}")
    mover.ask("motion on")
    watcher = open_client()
    mover.send(f"{verb}\n")
    wait_until_moving(watcher)
    watcher.close()
    assert mover.read_line() == "ok"
    assert mover.ask("status") == "ok idle"
    if verb != "rand":
        assert mover.ask("where") == "ok 0,0,0,0,0,0,0"


def test_bad_motion_lines_change_nothing(server: ServerThread, open_client):
    client = open_client()
    client.ask("radians")
    for line, error in [
        ("speed 0", "error: speed: 0 is outside 1..100"),
        ("speed 101", "error: speed: 101 is outside 1..100"),
        ("speed nan", "error: speed: bad number 'nan'"),
        ("motion fast", "error: motion: unknown mode 'fast'; choose off, on or follow"),
    ]:
        assert client.ask(line).startswith(error)
    assert client.ask("speed") == "ok 50"
    assert client.ask("motion") == "ok off"
    client.ask("motion on")
    assert client.ask("j 1,2,3").startswith("error: joints needs 7 values")
    assert client.ask("move 1 9").startswith("error: joint_l (index 1)")  # 9 rad
    assert client.ask("status") == "ok idle"  # a rejected target never starts a motion
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"


def test_a_waiting_client_that_leaves_costs_nothing(server: ServerThread, open_client):
    mover = open_client("on", 30)
    other = open_client()
    mover.send(f"j {FAR}\n")
    wait_until_moving(other)
    mover.sock.close()
    assert other.ask("wait") == "ok"  # the move goes on to its end
    other.ask("degrees")
    assert other.ask("where") == f"ok {FAR}"


def test_limits_all_gives_the_motion_limits_in_the_connection_units(server, open_client):
    client = open_client()
    client.ask("radians")
    limits = motion_limits(server.robot)
    radians = client.ask("limits all")[3:].split(",")
    assert radians[0] == (
        f"{server.robot.lower[0]:.10g}..{server.robot.upper[0]:.10g} rad "
        f"v={limits.velocity[0]:.10g} a={limits.acceleration[0]:.10g} j={limits.jerk[0]:.10g}"
    )
    client.ask("degrees")
    first = client.ask("limits all")[3:].split(",")[0]
    assert f"v={math.degrees(limits.velocity[0]):.10g}" in first
    assert client.ask("limits").count("v=") == 0  # the old reply is unchanged
