"""Cartesian commands through the real server: tool, ik, moveto, movel, lspeed."""

from __future__ import annotations

import math
import re

import numpy as np
import pinocchio as pin
import pytest
from support import ROBOTS, ServerThread, load_robot

from c2rviz.motion.limits import motion_limits


def pose_of(reply: str) -> pin.SE3:
    x, y, z, roll, pitch, yaw = (float(v) for v in reply[3:].split(","))
    return pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))


def errors(a: pin.SE3, b: pin.SE3) -> tuple[float, float]:
    """Position [m] and orientation [rad] difference."""
    delta = a.actInv(b)
    return float(np.linalg.norm(a.translation - b.translation)), float(
        np.linalg.norm(pin.log3(delta.rotation))
    )


def text(values) -> str:  # type: ignore[no-untyped-def]
    return ",".join(f"{v:.12g}" for v in values)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_ik_then_joints_reaches_the_pose_for_200_targets(start_server, connect, name: str):
    server = start_server(name)
    client = connect(server)
    robot = load_robot(name)
    rng = np.random.default_rng(7)
    targets = []
    for _ in range(200):
        placement = robot.ee_pose(robot.random(rng))
        rpy = pin.rpy.matrixToRpy(placement.rotation)
        targets.append((placement, text([*placement.translation, *rpy])))
    client.send("".join(f"ik {line}\n" for _, line in targets))
    solutions = [client.read_line() for _ in targets]
    solved = 0
    for (placement, _), reply in zip(targets, solutions):
        if not reply.startswith("ok "):
            assert reply.startswith("error: pose unreachable"), reply
            continue
        solved += 1
        assert client.ask(f"joints {reply[3:]}") == "ok"
        distance, angle = errors(placement, pose_of(client.ask("pose")))
        assert distance <= 1e-4 and angle <= math.radians(0.1)
    assert solved >= 198
    assert server.q != robot.home  # the joints lines moved it; ik alone never does


def test_ik_moves_nothing_and_answers_in_the_connection_units(server: ServerThread, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask("j 10,30,0,-40,0,50,0")
    pose = client.ask("pose")[3:]
    client.ask("home")
    degrees = client.ask(f"ik {pose}")
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"
    client.ask("radians")
    x, y, z, roll, pitch, yaw = (float(v) for v in pose.split(","))
    rad = f"{x},{y},{z},{math.radians(roll)},{math.radians(pitch)},{math.radians(yaw)}"
    radians = client.ask(f"ik {rad}")
    np.testing.assert_allclose(
        np.radians([float(v) for v in degrees[3:].split(",")]),
        [float(v) for v in radians[3:].split(",")],
        atol=1e-6,
    )


@pytest.mark.parametrize("mode", ["off", "on"])
@pytest.mark.parametrize("verb", ["moveto", "movel"])
def test_moveto_and_movel_in_either_motion_mode_and_either_unit(
    server: ServerThread, connect, mode: str, verb: str
):
    client = connect(server)
    client.ask("j 0.17,0.52,0,-0.7,0,0.87,0")
    target = pose_of(client.ask("pose"))
    client.ask("degrees")
    in_degrees = client.ask("pose")[3:]
    client.ask("radians")
    in_radians = client.ask("pose")[3:]
    for unit, pose in (("degrees", in_degrees), ("radians", in_radians)):
        for line in ("radians", "motion off", "j 0.1,0.4,0,-0.6,0,0.7,0", f"motion {mode}", unit):
            assert client.ask(line) == "ok"
        first = server.call(lambda: len(server.scene.joints))
        assert client.ask(f"{verb} {pose}") == "ok"  # with motion on: on arrival
        assert client.ask("status") == "ok idle"
        shown = server.call(lambda: len(server.scene.joints)) - first
        assert shown == 1 if mode == "off" else shown > 10  # at once, or travelled
        client.ask("radians")
        distance, angle = errors(target, pose_of(client.ask("pose")))
        assert distance <= 1e-4 and angle <= math.radians(0.1), (unit, distance, angle)


def test_a_tool_offset_moves_pose_and_ik_together(server: ServerThread, connect):
    client = connect(server)
    flange = pose_of(client.ask("pose"))
    assert client.ask("tool") == "ok 0,0,0,0,0,0"
    assert client.ask("tool 0,0,0.1,0,0,0") == "ok"
    assert client.ask("tool") == "ok 0,0,0.1,0,0,0"
    other = connect(server)  # the tool belongs to the robot: every connection sees it
    tcp = pose_of(other.ask("pose"))
    np.testing.assert_allclose(
        tcp.translation, (flange * pin.SE3(np.eye(3), np.array([0, 0, 0.1]))).translation, atol=1e-9
    )
    client.ask("j 0.2,0.5,0,-0.6,0,0.8,0")
    target = client.ask("pose")[3:]
    client.ask("home")
    assert client.ask(f"moveto {target}") == "ok"
    distance, _ = errors(pose_of("ok " + target), pose_of(client.ask("pose")))
    assert distance <= 1e-4


UNREACHABLE = (
    r"error: pose unreachable: (the closest reachable tool pose is [\d.]+ mm and [\d.]+ deg away"
    r"|the target is [\d.]+ m from the arm's first joint, which reaches [\d.]+ m at most: "
    r"every tool pose is at least [\d.]+ mm away), over the 0\.1 mm( / 0\.1 deg)? tolerance"
)


@pytest.mark.parametrize(
    "pose",
    ["2.5,0,0.5,0,0,0", "0,0,-0.5,0,0,0", "0.3,0,0,0,0,0", "0,0,1.45,3.14159,0,0"],
    ids=["2m-away", "under-the-base", "tool-up-at-the-floor", "stretched-up-tool-down"],
)
def test_unreachable_poses_say_how_far_and_change_nothing(server: ServerThread, connect, pose):
    client = connect(server)
    client.ask("j 0.1,0.2,0,0,0,0,0")
    before = client.ask("where")
    for verb in ("ik", "moveto", "movel"):
        reply = client.ask(f"{verb} {pose}")
        if verb == "movel":  # the line may be found blocked before its end is solved
            assert re.fullmatch(UNREACHABLE, reply) or reply.startswith(
                "error: straight line blocked"
            ), reply
        else:
            assert re.fullmatch(UNREACHABLE, reply), reply
        assert client.ask("where") == before


def test_movel_keeps_the_tool_on_the_line_within_lspeed_and_the_limits(
    server: ServerThread, connect
):
    client = connect(server)
    client.ask("j 0.1,0.4,0,-0.6,0,0.7,0")
    start = pose_of(client.ask("pose"))
    goal = start.copy()
    goal.translation = start.translation + np.array([0.0, 0.25, -0.1])
    rpy = pin.rpy.matrixToRpy(goal.rotation)
    for line in ("motion on", "speed 100", "lspeed 0.2"):
        assert client.ask(line) == "ok"
    first = server.call(lambda: len(server.scene.joints))
    assert client.ask(f"movel {text([*goal.translation, *rpy])}") == "ok"
    times, joints = server.call(lambda: (list(server.scene.times), list(server.scene.joints)))
    times, joints = np.array(times[first:]), np.array(joints[first:])
    robot = server.robot
    points = np.array([robot.ee_pose(q).translation for q in joints])
    direction = (goal.translation - start.translation) / np.linalg.norm(
        goal.translation - start.translation
    )
    offsets = points - start.translation
    off_line = np.linalg.norm(offsets - np.outer(offsets @ direction, direction), axis=1)
    assert off_line.max() <= 1e-3
    dt = np.diff(times)
    keep = dt > 1e-6
    tool_speed = np.linalg.norm(np.diff(points, axis=0), axis=1)[keep] / dt[keep]
    assert tool_speed.max() <= 0.2 * 1.02
    joint_speed = np.abs(np.diff(joints, axis=0))[keep] / dt[keep, None]
    assert (joint_speed <= np.array(motion_limits(robot).velocity) * 1.02).all()
    distance, angle = errors(goal, pose_of(client.ask("pose")))
    assert distance <= 1e-4 and angle <= math.radians(0.1)
    assert client.ask("lspeed") == "ok 0.2"


@pytest.mark.wall_clock
def test_stop_during_movel_brakes_on_the_line_short_of_the_goal(server: ServerThread, connect):
    mover, other = connect(server), connect(server)
    mover.ask("j 0.1,0.4,0,-0.6,0,0.7,0")
    start = pose_of(mover.ask("pose"))
    goal = start.copy()
    goal.translation = start.translation + np.array([0.0, 0.25, -0.1])
    rpy = pin.rpy.matrixToRpy(goal.rotation)
    for line in ("motion on", "speed 100", "lspeed 0.05"):  # ~5.4 s on the line
        assert mover.ask(line) == "ok"
    first = server.call(lambda: len(server.scene.joints))
    mover.send(f"movel {text([*goal.translation, *rpy])}\n")
    while np.linalg.norm(pose_of(other.ask("pose")).translation - start.translation) < 0.03:
        pass  # until the tool is 3 cm down the line, at its speed
    assert other.ask("stop") == "ok"  # at rest
    assert mover.read_line().startswith("error: motion stopped by tcp ")
    times, joints = server.call(lambda: (list(server.scene.times), list(server.scene.joints)))
    times, joints = np.array(times[first:]), np.array(joints[first:])
    points = np.array([server.robot.ee_pose(q).translation for q in joints])
    direction = (goal.translation - start.translation) / np.linalg.norm(
        goal.translation - start.translation
    )
    offsets = points - start.translation
    along = offsets @ direction
    assert np.linalg.norm(offsets - np.outer(along, direction), axis=1).max() <= 1e-3
    assert (np.diff(along) >= -1e-9).all()  # forward only, no jump back
    assert 0.0 < along[-1] < np.linalg.norm(goal.translation - start.translation) - 0.01
    # It slowed down to rest rather than halting at speed: the last step was slow.
    speeds = np.diff(along) / np.maximum(np.diff(times), 1e-9)
    moving = np.flatnonzero(np.diff(along) > 1e-9)
    assert speeds[moving[-1]] < 0.5 * speeds.max()
    np.testing.assert_allclose(pose_of(other.ask("pose")).translation, points[-1], atol=1e-9)


def test_movel_across_a_joint_limit_is_refused_before_the_arm_moves(start_server, connect):
    server = start_server("fanuc_lrmate200id")
    client = connect(server)
    client.ask("degrees")
    client.ask("j 160,20,0,0,-60,0")  # joint_1 near its +170 deg limit
    before = client.ask("where")
    pose = client.ask("pose")[3:].split(",")
    x, y = float(pose[0]), float(pose[1])
    # Swing the tool round the base past the limit, along a chord.
    target = f"{x},{-y - 0.3},{pose[2]},{pose[3]},{pose[4]},{pose[5]}"
    reply = client.ask(f"movel {target}")
    assert re.fullmatch(r"error: straight line blocked at \d+% of the way: .*", reply), reply
    assert client.ask("where") == before


def test_moveto_marker_and_bad_cartesian_lines(server: ServerThread, connect):
    client = connect(server)
    client.ask("j 0.2,0.5,0,-0.6,0,0.8,0")
    client.ask("mark")
    marked = client.ask("pose")
    client.ask("home")
    assert client.ask("moveto marker 1") == "ok"
    distance, _ = errors(pose_of(marked), pose_of(client.ask("pose")))
    assert distance <= 1e-4
    assert (
        client.ask("moveto marker 2")
        == "error: no marker 2: this robot has markers 1..1 (1 is the oldest)"
    )
    for line, error in [
        ("ik 1,2,3,4", "ik: needs 3 values (x,y,z) or 6 (x,y,z,roll,pitch,yaw), got 4"),
        ("ik 1,2,3", "point unreachable: the target is 3.422 m from the arm's first joint"),
        ("movel 1,2,3,0,0,nan", "bad number 'nan'"),
        ("lspeed 0", "lspeed: 0 m/s is outside 0.001..5"),
        ("lspeed 9", "9 m/s is outside 0.001..5"),
        ("lspeed 1e-320", "lspeed: 9.99989e-321 m/s is outside 0.001..5"),
        ("ik 1e300,0,0,0,0,0", "ik: x = 1e+300 m is outside -1000..1000 m"),
        ("tool 1e300,0,0,0,0,0", "tool: x = 1e+300 m is outside -10..10 m"),
        ("mark 1e308,0,0,0,0,0", "mark: x = 1e+308 m is outside -1000..1000 m"),
        ("moveto 0,0,1,0,2e6,0", "moveto: pitch = 2e+06 is outside -1e+06..1e+06"),
        ("moveto marker x", "marker needs a number from 1"),
        ("tool 1,2", "tool: needs 6 values, got 2"),
    ]:
        reply = client.ask(line)
        assert reply.startswith("error: ") and error in reply, reply
    assert client.ask("lspeed") == "ok 0.25"


def test_a_point_alone_is_a_target_with_any_orientation(server: ServerThread, connect):
    """Issue 30.4: `x,y,z` alone wherever a target is taken; the tool point goes there."""
    client = connect(server)
    client.ask("degrees")
    for line in ("moveto 0.5,0.3,0.9", "movel 0.5,0.1,0.9"):
        assert client.ask(line) == "ok", line
        x, y, z = (float(v) for v in client.ask("pose").removeprefix("ok ").split(",")[:3])
        want = [float(v) for v in line.split()[1].split(",")]
        assert max(abs(a - b) for a, b in zip((x, y, z), want)) <= 1e-4, (line, x, y, z)
    q = client.ask("ik 0.4,-0.2,1.0")
    assert q.startswith("ok ") and len(q.split(",")) == 7, q


def test_a_pose_reads_back_as_sent_near_pitch_90(server: ServerThread, connect):
    """Issue 30.5: the canonical form at pitch +-90 (roll 0, yaw carrying the rotation)."""
    client = connect(server)
    client.ask("degrees")
    assert client.ask("moveto 0.6,0.2,1.0,0,90,0") == "ok"
    x, y, z, roll, pitch, yaw = (
        float(v) for v in client.ask("pose").removeprefix("ok ").split(",")
    )
    assert (round(x, 4), round(y, 4), round(z, 4)) == (0.6, 0.2, 1.0)
    assert (roll, pitch, yaw) == (0.0, 90.0, 0.0)
