"""Faults through the text door, on the virtual clock: each kind's rule, the schedule,
the listing, bad input refused with nothing changed, and the same replies with the same
seed (noise and jitter included)."""

from __future__ import annotations

import asyncio
import inspect
import re

import pytest
from support import Client, load_robot

from c2rviz.errors import MotionInterrupted
from c2rviz.session import Session
from c2rviz.session.services import Services
from c2rviz.testing.server import TestServer
from c2rviz.transports.rosbridge.inputs import joint_trajectory
from c2rviz.transports.rosbridge.messages import JointTrajectory, TrajectoryPoint
from c2rviz.world.virtual_clock import VirtualClock
from c2rviz.world.world import World

FAR = "1,0.5,0.3,-0.5,0.2,0.5,0.1"  # radians, motoman_sia20d
STOP_RE = re.compile(r"emergency stop since t=(\d+\.\d{3}) \(fault clear estop, then reset\)")


def values(reply: str) -> list[float]:
    assert reply.startswith("ok "), reply
    return [float(v) for v in reply.split()[1].split(",")]


MOVES = ["joints " + FAR, "move 0 0.5", "home", "rand", "clear"]
"""A move of each family: every one of them is refused during a stop."""


@pytest.mark.c2rviz(clock="virtual", motion="on", speed=20)
def test_an_estop_halts_the_arm_and_refuses_every_move_until_clear_and_reset(
    c2rviz_server, connect
):
    client = connect(c2rviz_server)
    assert client.ask("fault after 0.5 estop") == "ok"
    stopped = client.ask("joints " + FAR)  # its arrival never comes
    found = STOP_RE.fullmatch(stopped.removeprefix("error: "))
    assert found, stopped
    since = float(found.group(1))
    assert client.ask("faults") == f"ok estop since {since:.3f}"
    halted = values(client.ask("where"))
    assert 0 < halted[0] < 1  # stopped on its way, where it was
    assert client.ask("status") == "ok idle"
    x, y, z, *rpy = values(client.ask("pose"))
    for line in [*MOVES, "movel " + ",".join(map(str, [x, y, z - 0.01, *rpy]))]:
        assert client.ask(line) == f"error: emergency stop since t={since:.3f} " + (
            "(fault clear estop, then reset)"
        ), line
    assert c2rviz_server.run("joints " + FAR).startswith("error: emergency stop since")
    assert values(client.ask("where")) == halted  # nothing moved
    assert client.ask("reset").startswith("error: emergency stop since")
    assert client.ask("fault clear estop") == "ok"
    assert client.ask("move 0 0.5") == f"error: emergency stop since t={since:.3f} " + (
        "(reset to move again)"
    )
    assert client.ask("faults") == f"ok estop released, reset needed since {since:.3f}"
    assert client.ask("reset") == "ok"
    assert client.ask("faults") == "ok none"
    assert client.ask("joints " + FAR) == "ok"
    assert values(client.ask("where")) == pytest.approx(values("ok " + FAR))


@pytest.mark.c2rviz(clock="virtual", motion="on", speed=20)
def test_a_protective_stop_brakes_on_the_path_and_holds_until_reset(c2rviz_server, connect):
    client = connect(c2rviz_server)
    start = c2rviz_server.now()
    assert client.ask("fault after 1 protective") == "ok"
    reply = client.ask("joints " + FAR)
    assert re.fullmatch(r"error: protective stop since t=\d+\.\d{3} \(reset to move again\)", reply)
    assert c2rviz_server.now() > start + 1.0  # it came to rest after braking, not at once
    where = values(client.ask("where"))
    assert 0 < where[0] < 1
    assert client.ask("move 0 0") == reply  # the same stop, the same words
    assert client.ask("reset") == "ok"
    assert client.ask("move 0 0") == "ok"


@pytest.mark.c2rviz(clock="virtual", motion="on", speed=50)
def test_a_stalled_joint_stays_and_the_move_ends_with_its_name(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("move 1 0.31") == "ok"
    assert client.ask("fault stall joint_l") == "ok"
    assert client.ask("joints 0.2,0.6,0,0,0,0,0") == "error: joint_l stalled at 0.31 rad"
    assert values(client.ask("where")) == pytest.approx([0.2, 0.31, 0, 0, 0, 0, 0])
    assert values(client.ask("target")) == pytest.approx([0.2, 0.6, 0, 0, 0, 0, 0])
    assert client.ask("move 0 -0.2") == "error: joint_l stalled at 0.31 rad"  # still wants 0.6
    assert client.ask("joints -0.2,0.31,0,0,0,0,0") == "ok"  # joint_l need not move
    assert client.ask("motion off") == "ok"
    assert client.ask("joints 0,0,0.4,0,0,0,0") == "error: joint_l stalled at 0.31 rad"
    assert values(client.ask("where")) == pytest.approx([0, 0.31, 0.4, 0, 0, 0, 0])
    assert client.ask("fault clear stall") == "ok"
    assert client.ask("motion on") == "ok"
    assert client.ask("joints 0,0,0.4,0,0,0,0") == "ok"  # from where the arm stands
    assert values(client.ask("where")) == pytest.approx([0, 0, 0.4, 0, 0, 0, 0])


@pytest.mark.c2rviz(clock="virtual", plan_seed=4)
def test_noise_is_on_reported_values_only(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("joints " + FAR) == "ok"
    assert client.ask("fault noise 0.01") == "ok"
    first, second = values(client.ask("where")), values(client.ask("where"))
    assert first != second
    assert first == pytest.approx(values("ok " + FAR), abs=0.06)  # 6 sigma
    assert client.ask("target") == "ok " + FAR  # commanded: exact
    assert client.ask("degrees") == "ok"
    assert client.ask("fault noise 0.5") == "ok"
    assert client.ask("faults").startswith("ok noise 0.5 since ")
    assert client.ask("radians") == "ok"
    assert client.ask("faults").startswith("ok noise 0.008726646")
    assert client.ask("fault clear noise") == "ok"
    assert client.ask("where") == "ok " + FAR


@pytest.mark.c2rviz(clock="virtual")
def test_latency_delays_replies_on_the_worlds_clock(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault latency 200") == "ok"
    start = c2rviz_server.now()
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"
    assert client.ask("names").startswith("ok motoman_sia20d")
    assert c2rviz_server.now() - start == pytest.approx(0.4)
    assert client.ask("fault latency 100,50") == "ok"
    start = c2rviz_server.now()
    client.ask("where")
    assert 0.1 <= c2rviz_server.now() - start <= 0.15
    assert client.ask("fault clear latency") == "ok"  # its own reply still late
    start = c2rviz_server.now()
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"
    assert c2rviz_server.now() == start


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_latency_comes_after_a_reply_that_waits(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault latency 500") == "ok"
    start = c2rviz_server.now()
    assert client.ask("sleep 1") == "ok"
    assert c2rviz_server.now() - start == pytest.approx(1.5)


def test_disconnect_closes_this_robots_clients(c2rviz_server, connect):
    first, second = connect(c2rviz_server), connect(c2rviz_server)
    assert second.ask("where") == "ok 0,0,0,0,0,0,0"
    assert first.ask("fault disconnect") == "ok"  # its reply first
    assert first.closed_by_server()
    assert second.closed_by_server()
    again = connect(c2rviz_server)
    assert again.ask("faults") == "ok none"  # nothing lasts


@pytest.mark.c2rviz(clock="virtual")
def test_scheduled_faults_begin_on_the_clock_and_clear_takes_them(c2rviz_server, connect):
    client = connect(c2rviz_server)
    origin = c2rviz_server.call(lambda: c2rviz_server.world.faults.origin)
    now = c2rviz_server.now() - origin
    assert client.ask("fault at 5 estop") == "ok"
    assert client.ask("fault after 2 stall 3") == "ok"
    assert client.ask("fault after 3 noise 0.1") == "ok"
    due = now + 2
    assert client.ask("faults") == (
        f"ok stall joint_u at {due:.3f}; noise 0.1 at {now + 3:.3f}; estop at 5.000"
    )
    assert client.ask("sleep 2.5") == "ok"
    assert client.ask("faults") == (
        f"ok stall joint_u since {due:.3f}; noise 0.1 at {now + 3:.3f}; estop at 5.000"
    )
    assert client.ask("fault clear all") == "ok"
    assert client.ask("faults") == "ok none"
    assert client.ask("sleep 5") == "ok"
    assert client.ask("faults") == "ok none"
    assert client.ask("move 0 1") == "ok"


@pytest.mark.parametrize(
    ("line", "error"),
    [
        ("fault bogus", "unknown fault 'bogus'"),
        ("fault stall joint_q", "no joint 'joint_q': motoman_sia20d has joint_s, joint_l"),
        ("fault stall 7", "no joint '7'"),
        ("fault after -1 estop", "S '-1' is not a time within 0..1e+06 s"),
        ("fault noise -0.1", "noise SIGMA -0.1 is outside"),
        ("fault latency 1,2,3", "latency needs MS[,JITTER]"),
        ("fault at 0 estop", "T 0 s has passed"),
    ],
)
@pytest.mark.c2rviz(clock="virtual")
def test_bad_faults_are_refused_and_change_nothing(c2rviz_server, connect, line, error):
    client = connect(c2rviz_server)
    assert client.ask("sleep 0.1") == "ok"
    reply = client.ask(line)
    assert reply.startswith("error: fault: ") and error in reply, reply
    assert client.ask("faults") == "ok none"
    assert client.ask("move 0 1") == "ok"


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_watch_tells_faults_as_events(c2rviz_server, connect):
    watcher, client = connect(c2rviz_server), connect(c2rviz_server)
    assert watcher.ask("watch 1").startswith("ok")
    for line in ["fault estop", "fault stall joint_l", "fault noise 0.01", "fault latency 5,1"]:
        assert client.ask(line) == "ok"
    for line in ["fault clear estop", "reset", "fault clear all"]:
        assert client.ask(line) == "ok"
    wanted = [
        "event fault estop",
        "event fault stall joint_l",
        "event fault noise 0.01",
        "event fault latency 5,1",
        "event cleared estop",
        "event reset",
        "event cleared stall joint_l",
        "event cleared noise 0.01",
        "event cleared latency 5,1",
    ]
    seen: list[str] = []
    while len(seen) < len(wanted):
        line = watcher.read_line()
        assert line, "the stream ended"
        if line.startswith("event"):
            seen.append(line)
    assert seen == wanted


SCRIPT = [
    "motion on",
    "fault noise 0.02",
    "fault latency 30,20",
    "joints " + FAR,
    "where",
    "fault after 0.2 stall 2",
    "joints 0,0,0,0,0,0,0",
    "where",
    "rand",
    "where",
    "faults",
]


def replies_of(seed: int) -> list[str]:
    server = TestServer({"clock": "virtual", "plan_seed": seed}).start()
    try:
        client = Client(server.host, server.port)
        try:
            out = [client.ask(line) for line in SCRIPT]
            out.append(f"{server.now():.9f}")
            return out
        finally:
            client.close()
    finally:
        server.stop()


def test_the_same_seed_gives_the_same_replies():
    first = replies_of(11)
    assert first == replies_of(11)
    assert first != replies_of(12)
    assert first[6].startswith("error: joint_e stalled at ")  # the stall began mid-move


@pytest.mark.c2rviz(cell="twoarms", clock="virtual")
def test_faults_belong_to_one_robot_of_a_cell(c2rviz_server, connect):
    left = connect(c2rviz_server)  # the first robot's port
    right = Client(c2rviz_server.host, c2rviz_server.ports["right"])
    try:
        assert left.ask("fault estop") == "ok"
        assert left.ask("move 0 0.5").startswith("error: emergency stop since")
        assert right.ask("move 0 0.5") == "ok"  # the other robot goes on
        assert right.ask("faults") == "ok none"
        assert right.ask("fault disconnect") == "ok"
        assert right.closed_by_server()
        assert left.ask("faults").startswith("ok estop since")  # still connected
    finally:
        right.close()


@pytest.mark.c2rviz(clock="virtual", motion="follow", speed=20)
def test_watch_states_carry_the_noise(c2rviz_server, connect):
    watcher, client = connect(c2rviz_server), connect(c2rviz_server)
    assert client.ask("fault noise 0.01") == "ok"
    assert watcher.ask("watch 10").startswith("ok")
    assert client.ask("move 0 1") == "ok"
    assert client.ask("wait") == "ok"
    states = []
    while len(states) < 3:
        line = watcher.read_line()
        if line.startswith("state "):
            states.append([float(v) for v in line.split()[2].split(",")])
    assert all(any(v != 0.0 for v in q[1:]) for q in states)  # still joints, yet noisy
    assert all(abs(v) < 0.06 for q in states for v in q[1:])


@pytest.mark.c2rviz(clock="virtual")
def test_bye_still_closes_under_latency(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault latency 100") == "ok"
    assert client.ask("bye") == "ok bye"  # at once: the connection closes after it
    assert client.closed_by_server()


@pytest.mark.c2rviz(robot="fanuc_lrmate200id")
def test_a_stop_refuses_the_gripper_too(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("grip 1") == "ok"
    assert client.ask("fault protective") == "ok"
    assert client.ask("grip 0").startswith("error: protective stop since t=")
    assert client.ask("grip") == "ok 1"
    assert client.ask("reset") == "ok"
    assert client.ask("grip 0") == "ok"


@pytest.mark.parametrize(
    ("verb", "guard"),
    [("joints", "on"), ("movel", "on"), ("movel", "off"), ("moveto", "on"), ("moveto", "off")],
)
def test_a_move_checked_while_a_stop_came_and_went_never_plays(verb, guard) -> None:
    """A move asked before an estop whose check, line or IK is still off the loop when the
    estop is cleared and reset is refused, never played after the reset (a CRCL test saw
    the move asked during the stop arrive after it, under load)."""

    async def run() -> None:
        # Virtual time: no client holds it, so the move asked after the reset plays at once
        services = Services(World(load_robot("motoman_sia20d"), clock=VirtualClock()))
        mover, pendant = Session(services, "mover"), Session(services, "pendant")
        for setting in ("joints " + FAR, "motion on", "guard " + guard):  # off the upright
            assert mover.run(setting) == "ok"
        start = mover.state.q
        x, y, z, *rpy = values(str(mover.run("pose")))
        pose = f"{x},{y},{z - 0.05},{rpy[0]},{rpy[1]},{rpy[2]}"
        line = "joints 0.5,0.3,0.2,-0.4,0.1,0.4,0" if verb == "joints" else f"{verb} {pose}"
        asked = asyncio.ensure_future(_awaited(mover.run(line)))
        await asyncio.sleep(0)  # it has asked the worker, which answers on a later turn
        for step in ("fault estop", "fault clear estop", "reset"):
            assert pendant.run(step) == "ok", step
        with pytest.raises(MotionInterrupted, match=r"a stop \(estop at t=\d+\.\d{3}\) came while"):
            await asyncio.wait_for(asked, 100.0)
        assert mover.state.q == start and not mover.travel.active
        assert await _awaited(mover.run(line)) == "ok"  # asked after the reset: it plays
        services.close()

    asyncio.run(run())


async def _awaited(reply: object) -> object:
    return await reply if inspect.isawaitable(reply) else reply


@pytest.mark.parametrize("guard", ["on", "off"])
def test_a_rosbridge_trajectory_planned_while_a_stop_came_and_went_never_plays(guard) -> None:
    """The rosbridge door's trajectory, planned and checked off the loop, meets the same
    rule through ``Session.unstopped``."""

    async def run() -> None:
        services = Services(World(load_robot("motoman_sia20d")))
        mover, pendant = Session(services, "mover"), Session(services, "pendant")
        assert mover.run("guard " + guard) == "ok"
        names = mover.robot.joint_names[:2]
        points = tuple(TrajectoryPoint((0.2 * t, -0.1 * t), float(t)) for t in (1, 2))
        trajectory = JointTrajectory(tuple(names), points)
        asked = asyncio.ensure_future(joint_trajectory(mover, trajectory))
        await asyncio.sleep(0)  # it has asked the worker, which answers on a later turn
        for step in ("fault estop", "fault clear estop", "reset"):
            assert pendant.run(step) == "ok", step
        with pytest.raises(MotionInterrupted, match=r"a stop \(estop at t=\d+\.\d{3}\) came while"):
            await asyncio.wait_for(asked, 100.0)
        assert not mover.travel.active and mover.state.q == (0.0,) * 7
        await joint_trajectory(mover, trajectory)  # asked after the reset: it plays
        assert mover.travel.active
        services.close()

    asyncio.run(run())
