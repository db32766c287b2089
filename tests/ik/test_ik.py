"""Inverse kinematics and straight lines on real models (pink with daqp, Pinocchio).

Targets are made by forward kinematics of random in-limit configurations, so
each is reachable; every answer is checked with ``Robot.ee_pose`` (the same
Pinocchio truth the server reports), never with the solver's own FK.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from functools import cache

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import ROBOTS, ROOT, examples, load_robot

from c2rviz.errors import C2rvizError, JointCountError
from c2rviz.ik.line import LineBlocked, interpolate, plan_line
from c2rviz.ik.solver import IkSolver, Unreachable
from c2rviz.robot.catalogue import EXAMPLE_ROBOTS, example_robot_data_dir, example_robots
from c2rviz.robot.model import Robot

TREE = ROOT / "tests" / "data" / "tree_robot" / "tree.urdf"
POSITION_TOL_M = 1e-4  # the promise: 0.1 mm ...
ANGLE_TOL_RAD = math.radians(0.1)  # ... and 0.1 deg
BUNDLED = sorted(ROBOTS)
EXAMPLE_ARMS = sorted(EXAMPLE_ROBOTS)  # every serial arm the catalogue names


def erd_robot(name: str) -> Robot:
    """An example-robot-data arm; a missing package fails (it is in the test extra)."""
    if example_robot_data_dir() is None:
        pytest.fail("example-robot-data is not installed: pip install -e '.[test]'")
    entry = example_robots()[name]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


def any_robot(name: str) -> Robot:
    return load_robot(name) if name in ROBOTS else erd_robot(name)


@cache
def solver(name: str) -> IkSolver:
    return IkSolver(any_robot(name))


def errors(
    robot: Robot, q: tuple[float, ...], target: pin.SE3, tool: pin.SE3
) -> tuple[float, float]:
    """Position [m] and angle [rad] between the tool at ``q`` and ``target``."""
    pose = robot.ee_pose(q) * tool
    distance = float(np.linalg.norm(pose.translation - target.translation))
    angle = float(np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)))
    return distance, angle


def within_limits(robot: Robot, q: tuple[float, ...]) -> bool:
    return all(lo <= v <= hi for v, lo, hi in zip(q, robot.lower, robot.upper))


# --- solve: random reachable targets ---------------------------------------------------


@pytest.mark.parametrize("name", BUNDLED + EXAMPLE_ARMS)
def test_solves_random_reachable_targets(name: str) -> None:
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(2024)
    solved = 0
    for _ in range(200):
        target = robot.ee_pose(robot.random(rng))
        seed = robot.random(rng)  # a different configuration
        try:
            q = ik.solve(target, seed)
        except Unreachable:
            continue
        solved += 1
        distance, angle = errors(robot, q, target, pin.SE3.Identity())
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD, (q, distance, angle)
        assert within_limits(robot, q), q
    assert solved >= 198, f"{name}: {solved}/200 solved"


@settings(max_examples=examples(25), deadline=None)
@given(
    name=st.sampled_from(BUNDLED),
    target_at=st.lists(st.floats(0, 1), min_size=7, max_size=7),
    seed_at=st.lists(st.floats(0, 1), min_size=7, max_size=7),
)
def test_property_any_reachable_target_from_any_seed(
    name: str, target_at: list[float], seed_at: list[float]
) -> None:
    """Targets anywhere in the limits, the limits themselves included; any seed: an answer
    is always right (within the tolerances and the limits), and a refusal says how far
    its closest pose was, which is past the tolerances. How often a reachable target is
    refused (under 1 %) is test_solves_random_reachable_targets's to count."""
    ik = solver(name)
    robot = ik.robot

    def at(fractions: list[float]) -> list[float]:
        return [lo + f * (hi - lo) for f, lo, hi in zip(fractions, robot.lower, robot.upper)]

    target = robot.ee_pose(at(target_at))
    try:
        q = ik.solve(target, at(seed_at))
    except Unreachable as refused:
        assert refused.distance_m > POSITION_TOL_M or refused.angle_rad > ANGLE_TOL_RAD
        return
    distance, angle = errors(robot, q, target, pin.SE3.Identity())
    assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD
    assert within_limits(robot, q)


@pytest.mark.parametrize("name", BUNDLED)
def test_a_near_target_keeps_the_arm_near_its_seed(name: str) -> None:
    """Redundant or not, a small tool motion is a small joint motion (no branch jump)."""
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(5)
    for _ in range(20):
        seed = np.array(robot.random(rng))
        nudged = np.clip(seed + rng.uniform(-0.02, 0.02, robot.n), robot.lower, robot.upper)
        q = ik.solve(robot.ee_pose(nudged.tolist()), seed.tolist())
        assert np.abs(np.subtract(q, seed)).max() < 0.2


def test_a_seed_of_the_wrong_length_is_refused() -> None:
    ik = solver("kuka_lwr")
    with pytest.raises(JointCountError, match="joints needs 7 values, got 6"):
        ik.solve(ik.robot.ee_pose([0.0] * 7), [0.0] * 6)


def test_the_answer_is_repeatable() -> None:
    ik = solver("kuka_lwr")
    rng = np.random.default_rng(9)
    target, seed = ik.robot.ee_pose(ik.robot.random(rng)), ik.robot.random(rng)
    assert ik.solve(target, seed) == ik.solve(target, seed)


# --- the tool offset -------------------------------------------------------------------


@pytest.mark.parametrize("name", ["fanuc_lrmate200id", "kuka_lwr"])
def test_tool_offset(name: str) -> None:
    """The tool point reaches the target; the flange ends where the offset says."""
    ik = solver(name)
    robot = ik.robot
    tool = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.02, -0.03, 0.15]))
    rng = np.random.default_rng(11)
    for _ in range(20):
        target = robot.ee_pose(robot.random(rng)) * tool
        seed = robot.random(rng)
        q = ik.solve(target, seed, tool)
        distance, angle = errors(robot, q, target, tool)
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD
        # the flange ends where the tool says; solving for that flange pose bare agrees
        flange_target = target * tool.inverse()
        flange = robot.ee_pose(q)
        assert np.linalg.norm(flange.translation - flange_target.translation) < 5e-4
        bare = ik.solve(flange_target, seed)
        distance, angle = errors(robot, bare, flange_target, pin.SE3.Identity())
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD
        # and the tool point is not the flange: the offset moved the answer
        assert np.linalg.norm(robot.ee_pose(q).translation - target.translation) > 0.1
        np.testing.assert_allclose(ik.tool_pose(q, tool).homogeneous, (flange * tool).homogeneous)


# --- unreachable targets ---------------------------------------------------------------

MESSAGE = re.compile(
    r"pose unreachable: the closest reachable tool pose is (\d+\.\d+) mm and (\d+\.\d+) deg away"
    r", over the 0\.1 mm / 0\.1 deg tolerance"
)
BEYOND_REACH = re.compile(
    r"pose unreachable: the target is (\d+\.\d{3}) m from the arm's first joint, which reaches "
    r"(\d+\.\d{3}) m at most: every tool pose is at least (\d+\.\d+) mm away, over the 0\.1 mm "
    r"tolerance"
)


def decimals(figure: str) -> int:
    return len(figure.split(".")[1])


def sampled_best_cost(robot: Robot, target: pin.SE3, weight: float) -> tuple[float, float]:
    """Best hypot(distance, weight * angle) over random configurations, and the largest reach."""
    rng = np.random.default_rng(0)
    best, reach = math.inf, 0.0
    for _ in range(4000):
        pose = robot.ee_pose(robot.random(rng))
        distance = float(np.linalg.norm(pose.translation - target.translation))
        angle = float(np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)))
        best = min(best, math.hypot(distance, weight * angle))
        reach = max(reach, float(np.linalg.norm(pose.translation)))
    return best, reach


@pytest.mark.parametrize("name", BUNDLED)
@pytest.mark.parametrize("where", ["2 m away", "under the base"])
def test_unreachable_reports_the_closest_pose(name: str, where: str) -> None:
    ik = solver(name)
    robot = ik.robot
    position = [2.0, 0.0, 0.5] if where == "2 m away" else [0.0, 0.0, -0.3]
    target = pin.SE3(pin.rpy.rpyToMatrix(0.1, 0.2, 0.3), np.array(position))
    with pytest.raises(Unreachable) as caught:
        ik.solve(target, [min(max(0.0, lo), hi) for lo, hi in zip(robot.lower, robot.upper)])
    error = caught.value
    assert isinstance(error, C2rvizError)
    if where == "2 m away":  # refused by the reach bound: a lower bound, no pose searched
        beyond = BEYOND_REACH.fullmatch(str(error))
        assert beyond is not None, str(error)
        assert float(beyond[3]) == round(error.distance_m * 1e3, decimals(beyond[3]))
        assert error.reach_m is not None and error.angle_rad == 0.0
        assert float(beyond[1]) - float(beyond[2]) == pytest.approx(error.distance_m, abs=2e-3)
    else:
        match = MESSAGE.fullmatch(str(error))
        assert match is not None, str(error)
        assert float(match[1]) == round(error.distance_m * 1e3, decimals(match[1]))
        assert float(match[2]) == round(math.degrees(error.angle_rad), decimals(match[2]))
    weight = ik.settings.orientation_cost
    best, reach = sampled_best_cost(robot, target, weight)
    # no worse than 4000 random configurations, and no closer than the reach allows
    assert ik.cost(error.distance_m, error.angle_rad) <= best
    assert error.distance_m >= np.linalg.norm(position) - reach - 0.05
    assert error.distance_m > 0.005


def tree_with_limited_wrist() -> Robot:
    """The tree robot with its continuous wrist limited to +-90 deg (a string URDF)."""
    xml = TREE.read_text().replace(
        '<joint name="wrist" type="continuous">', '<joint name="wrist" type="revolute">'
    )
    xml = xml.replace(
        '<origin xyz="0.25 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>',
        '<origin xyz="0.25 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>'
        '<limit lower="-1.5707963267948966" upper="1.5707963267948966" effort="1" velocity="1"/>',
    )
    return Robot(pin.buildModelFromXML(xml, mimic=True), "base_link", "tool0")


def test_wrist_orientation_out_of_range() -> None:
    """Roll 135 deg with a +-90 deg wrist: position reached, 45 deg short."""
    robot = tree_with_limited_wrist()
    assert robot.upper[3] == pytest.approx(math.pi / 2)
    ik = IkSolver(robot)
    reachable = robot.ee_pose([0.2, 0.3, -0.6, 0.0])
    target = pin.SE3(reachable.rotation @ pin.rpy.rpyToMatrix(math.radians(135), 0, 0),
                     reachable.translation)  # fmt: skip
    with pytest.raises(Unreachable) as caught:
        ik.solve(target, [0.25, 0.0, 0.0, 0.0])
    assert str(caught.value) == (
        "pose unreachable: the closest reachable tool pose is 0.0 mm and 45.0 deg away, "
        "over the 0.1 mm / 0.1 deg tolerance"
    )


# --- prismatic, continuous and mimic joints --------------------------------------------


def test_prismatic_and_continuous_joints() -> None:
    robot = Robot.from_urdf(TREE, "base_link", "tool0")
    assert robot.prismatic[0] and robot.joints[3].continuous
    ik = IkSolver(robot)
    rng = np.random.default_rng(3)
    for _ in range(50):
        target = robot.ee_pose(robot.random(rng))
        q = ik.solve(target, robot.random(rng))
        distance, angle = errors(robot, q, target, pin.SE3.Identity())
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD
        assert within_limits(robot, q)
    # a continuous joint keeps the seed's turn: two turns up stays two turns up
    seed = [0.2, 0.3, -0.6, 4 * math.pi + 0.1]
    q = ik.solve(robot.ee_pose([0.2, 0.3, -0.6, 0.3]), seed)
    assert q[3] == pytest.approx(4 * math.pi + 0.3, abs=1e-4)


MIMIC_ARM = """<?xml version="1.0"?>
<robot name="mimic_arm">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2_follow" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="j2" multiplier="0.5" offset="0.1"/></joint>
  <joint name="j3" type="prismatic"><parent link="c"/><child link="tip"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="1" velocity="1"/></joint>
</robot>
"""


def test_a_mimic_joint_on_the_chain_follows_its_leader() -> None:
    robot = Robot(pin.buildModelFromXML(MIMIC_ARM, mimic=True), "base", "tip")
    assert robot.joint_names == ("j1", "j2", "j3")  # j2_follow is not an index
    ik = IkSolver(robot)
    rng = np.random.default_rng(4)
    for _ in range(30):
        wanted = robot.random(rng)
        target = robot.ee_pose(wanted)
        # 3 joints cannot set a full pose: the target is one they made, and only it
        q = ik.solve(target, robot.random(rng))
        distance, angle = errors(robot, q, target, pin.SE3.Identity())
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD


@pytest.mark.parametrize(("eelink", "joints"), [("finger_left", 5), ("finger_right", 4)])
def test_tree_ends_beside_or_through_a_mimic(eelink: str, joints: int) -> None:
    """finger_left's chain holds the finger joint; finger_right's mimic is off-chain-led."""
    robot = Robot.from_urdf(TREE, "base_link", eelink)
    assert robot.n == joints
    ik = IkSolver(robot)
    rng = np.random.default_rng(8)
    for _ in range(20):
        target = robot.ee_pose(robot.random(rng))
        q = ik.solve(target, robot.random(rng))
        distance, angle = errors(robot, q, target, pin.SE3.Identity())
        assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD


# --- straight lines --------------------------------------------------------------------


BENT_ELBOW = {  # arms well inside their workspace, away from limits and singularities
    "motoman_sia20d": (0.3, 0.4, 0.2, -1.2, 0.3, -0.6, 0.2),
    "fanuc_lrmate200id": (0.3, 0.2, -0.2, 0.3, -0.8, 0.2),
    "kuka_lwr": (0.3, 0.4, 0.2, -1.2, 0.3, -0.6, 0.2),
}


def distance_to_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    t = np.clip(np.dot(point - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return float(np.linalg.norm(point - (a + t * (b - a))))


@pytest.mark.parametrize("name", BUNDLED)
def test_a_short_line_in_free_space(name: str) -> None:
    ik = solver(name)
    robot = ik.robot
    q0 = list(BENT_ELBOW[name])
    start = ik.tool_pose(q0)
    goal = pin.SE3(
        start.rotation @ pin.rpy.rpyToMatrix(0.2, -0.1, 0.3),
        start.translation + np.array([0.08, -0.06, 0.05]),
    )
    line = plan_line(ik, q0, goal)
    waypoints = line.waypoints
    assert waypoints[0].q == tuple(q0) and waypoints[0].s == 0.0 and waypoints[-1].s == 1.0
    assert all(b.s > a.s for a, b in zip(waypoints, waypoints[1:]))
    assert line.length_m == pytest.approx(np.linalg.norm([0.08, -0.06, 0.05]))
    for waypoint in waypoints:
        pose = robot.ee_pose(waypoint.q)
        off_line = distance_to_segment(pose.translation, start.translation, goal.translation)
        assert off_line < 1e-3
        assert np.linalg.norm(pose.translation - line.pose_at(waypoint.s).translation) < 1e-4
        assert within_limits(robot, waypoint.q)
    distance, angle = errors(robot, waypoints[-1].q, goal, pin.SE3.Identity())
    assert distance <= POSITION_TOL_M and angle <= ANGLE_TOL_RAD
    # neighbours a few mm and at most a degree apart
    for a, b in zip(waypoints, waypoints[1:]):
        step = line.pose_at(a.s).actInv(line.pose_at(b.s))
        assert np.linalg.norm(step.translation) <= 0.005 + 1e-12
        assert np.linalg.norm(pin.log3(step.rotation)) <= math.radians(1) + 1e-12


def test_timestamps_respect_the_tool_speed_and_the_joint_limits() -> None:
    ik = solver("motoman_sia20d")
    q0 = BENT_ELBOW["motoman_sia20d"]
    start = ik.tool_pose(q0)
    goal = pin.SE3(start.rotation, start.translation + np.array([0.0, 0.2, -0.1]))
    line = plan_line(ik, q0, goal)
    joint_limits = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.05]  # a slow last joint
    speed, turn = 0.1, 0.5
    times = line.timestamps(speed, joint_limits, turn)
    assert times[0] == 0.0 and len(times) == len(line.waypoints)
    slowed = 0
    for (a, b), (ta, tb) in zip(zip(line.waypoints, line.waypoints[1:]), zip(times, times[1:])):
        dt = tb - ta
        assert dt > 0
        assert (b.s - a.s) * line.length_m / dt <= speed * (1 + 1e-9)
        joint_speed = np.abs(np.subtract(b.q, a.q)) / dt
        assert (joint_speed <= np.array(joint_limits) * (1 + 1e-9)).all()
        slowed += (b.s - a.s) * line.length_m / dt < speed * 0.99
    assert times[-1] >= line.length_m / speed
    assert slowed > 0  # the slow joint held the tool back somewhere
    with pytest.raises(ValueError):
        line.timestamps(0.0, joint_limits)


def test_a_line_through_a_joint_limit_is_refused_with_the_fraction() -> None:
    """Fanuc joint_1 (+-2.965 rad) must follow the wrist centre's azimuth past its limit."""
    ik = solver("fanuc_lrmate200id")
    robot = ik.robot
    q0 = [2.8, 0.3, 0.0, 0.0, -0.8, 0.0]
    start = ik.tool_pose(q0)
    p = start.translation
    azimuth = math.atan2(p[1], p[0])
    across = 0.4 * np.array([-math.sin(azimuth), math.cos(azimuth), 0.0])
    goal = pin.SE3(start.rotation, p + across)
    # the wrist centre rides along with the tool (fixed orientation); joint_1 follows its azimuth
    pin.framesForwardKinematics(robot.model, robot.data, robot.configuration(q0))
    wrist = robot.base_placement.actInv(robot.data.oMi[robot.model.getJointId("joint_5")])
    offset = wrist.translation - p
    fractions = np.linspace(0, 1, 100001)
    azimuths = [math.atan2(*(p + s * across + offset)[[1, 0]]) for s in fractions]
    expected = fractions[np.argmax(np.array(azimuths) >= robot.upper[0])]
    with pytest.raises(LineBlocked) as caught:
        plan_line(ik, q0, goal)
    blocked = caught.value
    assert blocked.joint == "joint_1"
    assert blocked.fraction == pytest.approx(expected, abs=2e-3)
    assert str(blocked) == (
        f"straight line blocked at {math.floor(blocked.fraction * 100)}% of the way: "
        "joint_1 reaches its limit"
    )


def test_a_prismatic_lift_at_its_limit_blocks_the_line() -> None:
    """Tree robot, tool pointing down, shoulder up 0.3 rad: going straight up, only the
    lift (0..0.5 m) moves the tool; the goal is reachable with the upper arm flipped."""
    robot = Robot.from_urdf(TREE, "base_link", "tool0")
    ik = IkSolver(robot)
    headroom = 0.345 * 0.25  # the lift runs out 34.5 % of the way up a 0.25 m line
    q0 = [0.5 - headroom, 0.3, math.pi / 2 - 0.3, 0.0]
    start = ik.tool_pose(q0)
    goal = pin.SE3(start.rotation, start.translation + np.array([0.0, 0.0, 0.25]))
    flipped = ik.solve(goal, q0)
    assert flipped[1] < 0  # another way there: the straight line is what is blocked
    with pytest.raises(LineBlocked) as caught:
        plan_line(ik, q0, goal)
    assert caught.value.joint == "lift"
    assert caught.value.fraction == pytest.approx(0.345, abs=1e-3)
    assert str(caught.value) == "straight line blocked at 34% of the way: lift reaches its limit"


def test_a_line_through_the_wrist_singularity_is_refused() -> None:
    """Fanuc, wrist bent 0.2 rad with joint_4 a hair off zero: straight up, the bend
    must pass zero while joint_4 turns half a turn in a few micrometres."""
    ik = solver("fanuc_lrmate200id")
    q0 = [0.0, 0.3, 0.0, 0.003, 0.2, 0.0]
    start = ik.tool_pose(q0)
    goal = pin.SE3(start.rotation, start.translation + np.array([0.0, 0.0, 0.15]))
    ik.solve(goal, q0)  # the goal itself is reachable
    with pytest.raises(LineBlocked) as caught:
        plan_line(ik, q0, goal)
    blocked = caught.value
    assert blocked.joint is None and blocked.joint_count is None
    assert abs(blocked.q[4]) < 0.005  # joint_5 straight: the wrist singularity
    assert 0.3 < blocked.fraction < 0.7
    percent = math.floor(blocked.fraction * 100)
    assert str(blocked) == f"straight line blocked at {percent}% of the way: passes a singularity"


def test_a_line_off_the_poses_of_a_four_joint_arm() -> None:
    """Tree robot (4 joints): between two reachable poses, the line and slerp leave
    the poses it can reach at once."""
    robot = Robot.from_urdf(TREE, "base_link", "tool0")
    ik = IkSolver(robot)
    q0 = [0.2, 0.3, -0.6, 0.0]
    with pytest.raises(LineBlocked) as caught:
        plan_line(ik, q0, robot.ee_pose([0.2, 0.3, -0.2, 0.5]))
    assert caught.value.joint_count == 4 and caught.value.fraction < 0.01
    assert str(caught.value) == (
        "straight line blocked at 0% of the way: the tool leaves the poses 4 joints can reach"
    )
    # lift, arm and wrist alone keep the tool on a line: those lines pass
    for q1 in ([0.3, 0.3, -0.6, 0.0], [0.2, 0.5, -0.6, 0.0], [0.2, 0.3, -0.6, 1.0]):
        assert plan_line(ik, q0, robot.ee_pose(q1)).waypoints[-1].s == 1.0


def test_a_line_to_an_unreachable_goal_says_so() -> None:
    ik = solver("kuka_lwr")
    q0 = BENT_ELBOW["kuka_lwr"]
    start = ik.tool_pose(q0)
    goal = pin.SE3(start.rotation, np.array([2.0, 0.0, 0.5]))
    with pytest.raises(Unreachable, match="pose unreachable"):
        plan_line(ik, q0, goal)


def test_interpolate_ends_and_middle() -> None:
    a = pin.SE3(pin.rpy.rpyToMatrix(0.1, 0.2, 0.3), np.array([0.0, 0.0, 1.0]))
    b = pin.SE3(pin.rpy.rpyToMatrix(-0.4, 0.5, 1.3), np.array([1.0, 2.0, 3.0]))
    np.testing.assert_allclose(interpolate(a, b, 0.0).homogeneous, a.homogeneous, atol=1e-12)
    np.testing.assert_allclose(interpolate(a, b, 1.0).homogeneous, b.homogeneous, atol=1e-12)
    mid = interpolate(a, b, 0.5)
    np.testing.assert_allclose(mid.translation, [0.5, 1.0, 2.0])
    half = np.linalg.norm(pin.log3(a.rotation.T @ mid.rotation))
    assert half == pytest.approx(np.linalg.norm(pin.log3(a.rotation.T @ b.rotation)) / 2)


def test_the_benchmark_script_runs() -> None:
    """benchmarks/ik_bench.py cannot rot: a quick run prints every row (no timing checked)."""
    root = ROOT
    done = subprocess.run(
        [sys.executable, str(root / "benchmarks" / "ik_bench.py"), "--quick", "--robots",
         "fanuc_lrmate200id"],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    for case in (r"random +\d+/20 ", r"near +\d+/20 ", r"2 m away +refused ", r"movel +\d+/\d+ "):
        assert re.search(f"^fanuc_lrmate200id +{case}", done.stdout, re.M), done.stdout
    assert "median to plan 0.5 m" in done.stdout
