"""``plan`` and ``guard plan`` through the real server (issue 28): around boxes on every arm,
the executed motion free by an independent check, on the checked path, within the limits,
arriving; and every bad request refused with one clear sentence, the arm unmoved."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from planning_scenes import (
    BUNDLED,
    IndependentCheck,
    Scene,
    blocked_scenes,
    distance_to_polyline,
    erd_folder,
    load,
    polyline_samples,
)
from support import Client, ServerThread

from c2rviz.collision import CollisionModel
from c2rviz.motion import motion_limits
from c2rviz.robot import Robot
from c2rviz.session import ServerLimits, SessionDefaults
from c2rviz.world.virtual_clock import VirtualClock

ARMS = [
    *BUNDLED,
    pytest.param(
        "panda",
        marks=pytest.mark.skipif(
            erd_folder() is None, reason="example-robot-data is not installed"
        ),
    ),
]
FINE_RAD = math.radians(0.2)  # [rad] independent samples of a path: 5 per check step
DT = 2e-3  # [s] samples of the motion played
SUMMARY = re.compile(r"ok (\d+) waypoints (\d+\.\d{3}) rad (\d+\.\d{3}) s")


def numbers(values: np.ndarray | tuple[float, ...]) -> str:
    return ",".join(repr(float(x)) for x in values)


@pytest.fixture
def serve() -> Iterator[Callable[..., tuple[ServerThread, Client]]]:
    """Factory: ``serve(robot)`` -> a live server on ``robot`` and a client (radians).

    On virtual time: these tests judge paths and frames, not how long a move takes on
    the wall, and the one client waits on the clock (a reply on arrival, ``wait``)."""
    started: list[tuple[ServerThread, Client]] = []

    def start(robot: Robot, **defaults: object) -> tuple[ServerThread, Client]:
        server = ServerThread(robot, ServerLimits(), clock=VirtualClock()).start()
        if defaults:
            server.services.defaults = SessionDefaults(**defaults)  # type: ignore[arg-type]
        client = Client(server.host, server.port)
        started.append((server, client))
        return server, client

    yield start
    for server, client in started:
        client.close()
        server.stop()


def furnish(client: Client, scene: Scene) -> None:
    for k, (size, centre) in enumerate(scene.boxes):
        assert client.ask(f"object box{k} box {numbers(size)} {numbers(centre)},0,0,0") == "ok"


def played(server: ServerThread, client: Client, line: str) -> tuple[str, object]:
    """Send ``line`` with ``motion follow`` (the reply as the arm leaves), take the path
    the world plays, wait for the arm; return the reply and the path."""
    assert client.ask("motion follow") == "ok"
    reply = client.ask(line)
    name = server.robot.name
    play = server.call(lambda: server.world.travel(name).path)
    assert client.ask("wait") == "ok"
    return reply, play


@pytest.mark.parametrize("name", ARMS)
def test_plan_goes_around_a_box_and_the_motion_stays_on_the_checked_path(serve, name: str):
    robot = load(name)
    limits = motion_limits(robot)
    low, high = np.array(robot.lower), np.array(robot.upper)
    (scene,) = blocked_scenes(CollisionModel(robot), 1, seed=31)
    server, client = serve(robot, plan_seed=11)  # a seed: the same path every run
    furnish(client, scene)
    check = IndependentCheck(name, scene)
    straight = polyline_samples(np.array([scene.start, scene.goal]), FINE_RAD)
    assert any(check.hits(q) for q in straight), "the box must be in the way"
    assert client.ask(f"j {numbers(scene.start)}") == "ok"
    assert client.ask("speed 100") == "ok"
    start_frame = server.call(lambda: len(server.scene.joints))
    reply, play = played(server, client, f"plan joints {numbers(scene.goal)}")
    match = SUMMARY.fullmatch(reply)
    assert match, reply
    shown = client.ask("plan")[3:].split(";")
    waypoints = np.array([[float(x) for x in row.split(",")] for row in shown])
    assert len(waypoints) == int(match.group(1)) >= 3  # it went around
    np.testing.assert_allclose(waypoints[0], scene.start, atol=1e-9)
    np.testing.assert_allclose(waypoints[-1], scene.goal, atol=1e-9)
    length = np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))
    assert float(match.group(2)) == pytest.approx(length, abs=2e-3)
    for q in polyline_samples(waypoints, FINE_RAD):
        assert check.hits(q) == [], f"the path touches {check.hits(q)} at {q}"
    # the motion played: on the polyline, free, within the limits, at the goal
    assert play is not None and play.joint_path.shape == waypoints.shape  # type: ignore[attr-defined]
    times = np.arange(play.start, play.arrival + DT, DT)  # type: ignore[attr-defined]
    qs = np.array([play.sample(t) for t in times])  # type: ignore[attr-defined]
    assert float(match.group(3)) == pytest.approx(play.duration, abs=2e-3)  # type: ignore[attr-defined]
    assert np.all(qs >= low) and np.all(qs <= high)
    assert distance_to_polyline(qs, waypoints).max() < 1e-6
    for q in qs[:: max(1, len(qs) // 400)]:
        assert check.hits(q) == [], f"the motion touches {check.hits(q)}"
    velocity = np.diff(qs, axis=0) / DT
    assert np.all(np.abs(velocity) <= np.array(limits.velocity) * (1 + 1e-6))
    frames = server.call(lambda: list(server.scene.joints[start_frame:]))
    assert all(check.hits(q) == [] for q in frames[:: max(1, len(frames) // 200)])
    np.testing.assert_allclose(frames[-1], scene.goal, atol=1e-12)
    assert client.ask("collisions") == "ok none"


def test_guard_plan_goes_around_where_guard_on_refuses(serve):
    robot = load("motoman_sia20d")
    (scene,) = blocked_scenes(CollisionModel(robot), 1, seed=8)
    server, client = serve(robot, plan_seed=3)
    furnish(client, scene)
    check = IndependentCheck("motoman_sia20d", scene)
    for line in (f"j {numbers(scene.start)}", "speed 100", "guard on", "motion on"):
        assert client.ask(line) == "ok"
    reply = client.ask(f"j {numbers(scene.goal)}")
    assert re.fullmatch(r"error: \w+ would hit box0 at \d+% of the move", reply), reply
    assert client.ask("guard plan") == "ok" and client.ask("guard") == "ok plan"
    reply, play = played(server, client, f"j {numbers(scene.goal)}")
    assert reply == "ok"
    waypoints = play.joint_path  # type: ignore[attr-defined]
    assert len(waypoints) >= 3
    times = np.arange(play.start, play.arrival + DT, 4 * DT)  # type: ignore[attr-defined]
    assert all(check.hits(play.sample(t)) == [] for t in times)  # type: ignore[attr-defined]
    np.testing.assert_allclose(server.q, scene.goal, atol=1e-12)
    # moveto under guard plan goes around too (its goal from the IK)
    assert client.ask(f"j {numbers(scene.start)}") == "ok"


def test_plan_pose_picks_an_ik_answer_that_plans_and_a_point_target(serve):
    robot = load("kuka_lwr")
    server, client = serve(robot)
    for line in ("degrees", "motion on", "speed 100", "j 0,30,0,-60,0,45,0"):
        assert client.ask(line) == "ok"
    pose = client.ask("pose")[3:]
    assert client.ask("j 0,-30,0,60,0,-45,0") == "ok"
    assert SUMMARY.fullmatch(client.ask(f"plan pose {pose}"))
    assert client.ask("pose") == f"ok {pose}"
    x, y, z = (float(v) for v in pose.split(",")[:3])
    assert client.ask("j 0,0,0,0,0,0,0") == "ok"
    assert SUMMARY.fullmatch(client.ask(f"plan pose {x},{y},{z}"))
    here = [float(v) for v in client.ask("pose")[3:].split(",")]
    np.testing.assert_allclose(here[:3], [x, y, z], atol=1e-4)


def test_plan_alone_replies_the_last_waypoints_in_the_connection_units(serve):
    server, client = serve(load("fanuc_lrmate200id"))
    assert client.ask("plan") == "ok none"
    assert client.ask("degrees") == "ok"
    match = SUMMARY.fullmatch(client.ask("plan joints 10,20,30,0,0,0"))
    assert match and match.group(1) == "2", "a free straight path is the path"
    assert float(match.group(2)) == pytest.approx(math.radians(math.hypot(10, 20, 30)), abs=1e-3)
    assert client.ask("plan") == "ok 0,0,0,0,0,0;10,20,30,0,0,0"
    assert client.ask("where") == "ok 10,20,30,0,0,0"  # motion off: shown at once


def test_the_same_seed_plans_the_same_path(serve):
    robot = load("kuka_lwr")
    (scene,) = blocked_scenes(CollisionModel(robot), 1, seed=5)
    paths = []
    for _ in range(2):
        server, client = serve(robot, plan_seed=1234)
        furnish(client, scene)
        assert client.ask(f"j {numbers(scene.start)}") == "ok"
        assert SUMMARY.fullmatch(client.ask(f"plan joints {numbers(scene.goal)}"))
        paths.append(client.ask("plan"))
    assert paths[0] == paths[1] and paths[0].count(";") >= 2


TRAP_URDF = """<?xml version="1.0"?>
<!-- a 3-joint arm: a thin rod (radius 2 cm) ending in a fat hand (a 16 cm cube) -->
<robot name="rod_and_hand">
  <link name="base"><collision><geometry><cylinder radius="0.05" length="0.1"/></geometry>
    <origin xyz="0 0 0.05"/></collision></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="shoulder"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3.1" upper="3.1" effort="1" velocity="1"/></joint>
  <link name="shoulder"/>
  <joint name="pitch" type="revolute"><parent link="shoulder"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
  <link name="rod"><collision><origin xyz="0.36 0 0" rpy="0 1.5707963 0"/>
    <geometry><cylinder radius="0.02" length="0.62"/></geometry></collision></link>
  <joint name="roll" type="revolute"><parent link="rod"/><child link="hand"/>
    <origin xyz="0.75 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="hand"><collision><geometry><box size="0.16 0.16 0.16"/></geometry></collision></link>
</robot>
"""


def test_an_enclosed_goal_gives_no_path_in_the_time_limit_and_nothing_moves(serve, tmp_path: Path):
    """The hand went through a wall's 8 cm hole on its rod; it cannot come back."""
    urdf = tmp_path / "trap.urdf"
    urdf.write_text(TRAP_URDF)
    server, client = serve(Robot.from_urdf(urdf, "base", "hand"))
    height, hole, x, depth = 0.1, 0.04, 0.56, 0.02
    for name, size, centre in [
        ("below", (depth, 4.0, 2.0), (x, 0.0, height - hole - 1.0)),
        ("above", (depth, 4.0, 2.0), (x, 0.0, height + hole + 1.0)),
        ("left", (depth, 2.0, 2 * hole), (x, hole + 1.0, height)),
        ("right", (depth, 2.0, 2 * hole), (x, -hole - 1.0, height)),
    ]:
        assert client.ask(f"object {name} box {numbers(size)} {numbers(centre)},0,0,0") == "ok"
    assert client.ask("j 3,0,0") == "ok" and client.ask("collisions") == "ok none"
    assert client.ask("plan timeout 0.3") == "ok"
    reply = client.ask("plan joints 0,0,0")
    match = re.fullmatch(r"error: no path found in 0\.3 s \((\d+) states\)", reply)
    assert match and int(match.group(1)) > 1000, reply
    assert client.ask("where") == "ok 3,0,0" and client.ask("plan") == "ok none"
    assert client.ask("guard plan") == "ok" and client.ask("motion on") == "ok"
    reply = client.ask("j 0,0,0")
    assert re.fullmatch(
        r"error: \w+ would hit \w+ at \d+% of the move, and no way around it: "
        r"no path found in 0\.3 s \(\d+ states\)",
        reply,
    ), reply
    assert client.ask("where") == "ok 3,0,0"


BAD = [
    ("plan joints 0,0,0,0,0,0,400", r"error: joint_t \(index 6\) = 400 deg is outside its limits "),
    ("plan joints 0,0,0", r"error: joints needs 7 values, got 3"),
    ("plan joints 90,60,0,0,0,0,0", r"error: the goal collides: link_\w+ would touch table"),
    ("plan pose 5,5,5,0,0,0", r"error: (the )?.*(reach|unreachable).*"),
    ("plan pose 1,2,3,4", r"error: plan: a pose is x,y,z or x,y,z,roll,pitch,yaw, not 4 values"),
    ("plan timeout nan", r"error: plan: bad number 'nan'.*"),
    ("plan timeout 1e9", r"error: plan timeout = 1000000000\.0 is not valid: give a number "),
    (
        "plan timeout 0",
        r"error: plan timeout = 0\.0 is not valid: give a number from 0\.001 to 60 s",
    ),
    (
        "plan resolution 50,0.005",
        r"error: plan: a joint step of 50 deg is outside 0\.00573\.\.11\.46 deg",
    ),
    ("plan resolution 1,1e9", r"error: plan: a tool step of 1e\+09 m is outside 0\.0001\.\.0\.1 m"),
    ("plan resolution 1", r"error: plan: resolution takes a joint step and a tool step"),
    ("plan around 1,2", r"error: plan: 'around' is not one of joints, pose, timeout, resolution"),
    ("plan joints", r"error: plan: joints needs values"),
]


@pytest.mark.parametrize(("line", "error"), BAD, ids=[line for line, _ in BAD])
def test_bad_plans_are_refused_clearly_and_nothing_moves(serve, line: str, error: str):
    server, client = serve(load("motoman_sia20d"))
    for setup in ("degrees", "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0", "motion on"):
        assert client.ask(setup) == "ok"
    assert client.ask("j 0,60,0,0,0,0,0") == "ok"
    before = server.call(lambda: len(server.scene.joints))
    reply = client.ask(line)
    assert re.match(error, reply), reply
    assert client.ask("where") == "ok 0,60,0,0,0,0,0"
    assert server.call(lambda: len(server.scene.joints)) == before
    assert client.ask("plan timeout") == "ok 1" and client.ask("plan resolution") == "ok 1,0.005"


def test_a_start_in_collision_names_the_pair(serve):
    server, client = serve(load("motoman_sia20d"))
    for line in ("degrees", "j 90,60,0,0,0,0,0", "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0"):
        assert client.ask(line) == "ok"
    reply = client.ask("plan joints 0,60,0,0,0,0,0")
    assert re.fullmatch(
        r"error: the start collides: link_\w+ touches table \(move it free first\)", reply
    ), reply
