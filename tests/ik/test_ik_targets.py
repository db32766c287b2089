"""IK of issue 30: round trips on every arm, the reach bound, point targets, honest refusals.

Targets are made by forward kinematics (so they are reachable) and every answer
is checked with ``Robot.ee_pose``, never with the solver's own kinematics.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pinocchio as pin
import pytest
from test_ik import BENT_ELBOW, BUNDLED, EXAMPLE_ARMS, errors, solver, within_limits

from c2rviz.ik import IkSolver, PointTarget, Unreachable, plan_line
from c2rviz.ik.chain import goal_in_world
from c2rviz.robot import Robot
from c2rviz.robot.frames import canonical_rpy

ALL_ARMS = BUNDLED + EXAMPLE_ARMS
PROMISE_M, PROMISE_RAD = 1e-4, math.radians(0.1)


def point_error(robot: Robot, q: tuple[float, ...], target: PointTarget) -> float:
    pose = robot.ee_pose(q)
    return float(np.linalg.norm(pose.translation - np.array(target.position)))


# --- round trips -----------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL_ARMS)
def test_round_trip_reads_back_exactly(name: str) -> None:
    """FK of a random configuration, solved from another: the pose comes back to 1e-9
    (the descent takes a step or two past the tolerance), never worse than the promise."""
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(31)
    solved = exact = 0
    for _ in range(50):
        target = robot.ee_pose(robot.random(rng))
        try:
            q = ik.solve(target, robot.random(rng))
        except Unreachable:
            continue
        solved += 1
        distance, angle = errors(robot, q, target, pin.SE3.Identity())
        assert distance <= PROMISE_M and angle <= PROMISE_RAD
        assert within_limits(robot, q)
        exact += distance <= 1e-9 and angle <= 1e-9
    assert solved >= 49, f"{name}: {solved}/50"
    assert exact >= solved - 2, f"{name}: {exact}/{solved} exact to 1e-9"


def test_two_solvers_give_the_same_answers() -> None:
    """Pure: the restarts' seed pool is drawn with a fixed seed, so a new solver agrees."""
    robot = solver("fanuc_lrmate200id").robot
    first, second = IkSolver(robot), IkSolver(robot)
    rng = np.random.default_rng(12)
    for _ in range(20):
        target, seed = robot.ee_pose(robot.random(rng)), robot.random(rng)
        assert first.solve(target, seed) == second.solve(target, seed)


def test_a_joint_of_two_turns_takes_the_turn_nearest_the_seed() -> None:
    """UR5 joints span +-360 deg: of two values with one pose, the one nearer the seed."""
    ik = solver("ur5")
    seed = [5.0, -1.0, 1.2, -0.8, 1.1, 0.4]
    other_turn = [seed[0] + 0.05 - math.tau, *seed[1:]]  # the same pose as joint 0 at 5.05
    assert ik.chain.to_chain(ik.chain.to_model(other_turn), seed)[0] == pytest.approx(5.05)
    assert ik.solve(ik.robot.ee_pose(other_turn), seed)[0] == pytest.approx(5.05, abs=1e-6)


# --- the reach bound -------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL_ARMS)
def test_no_configuration_leaves_the_reach_bound(name: str) -> None:
    """The bound is sound (it may refuse only the truly unreachable), with a tool too."""
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(5)
    tool = pin.SE3(pin.rpy.rpyToMatrix(0.2, 0.1, -0.3), np.array([0.03, -0.02, 0.12]))
    for offset in (None, tool):
        ik.chain.set_tool(offset)
        radius = ik.reach.radius_m()
        farthest = 0.0
        for _ in range(500):
            q = robot.random(rng)
            pose = ik.tool_pose(q, offset)
            world = ik.chain.base_placement.act(pose.translation)
            farthest = max(farthest, float(np.linalg.norm(world - ik.reach.center)))
        assert farthest <= radius + 1e-9
        assert farthest > 0.5 * radius  # and not absurdly loose


@pytest.mark.parametrize("name", ALL_ARMS)
@pytest.mark.parametrize("point", [False, True], ids=["pose", "point"])
def test_beyond_reach_is_refused_before_any_step(name: str, point: bool) -> None:
    ik = solver(name)
    robot = ik.robot
    far = np.array([2.5 * ik.reach.radius_m() + 1.0, 0.0, 0.2])
    target = PointTarget.at(far) if point else pin.SE3(pin.rpy.rpyToMatrix(0.1, 0.2, 0.3), far)
    steps = ik.steps
    with pytest.raises(Unreachable) as caught:
        ik.solve(target, robot.home)
    with pytest.raises(Unreachable):
        plan_line(ik, robot.home, target)
    assert ik.steps == steps  # not one descent step, Newton or pink
    refused = caught.value
    assert refused.reach_m is not None
    assert refused.reach_m == pytest.approx(ik.reach.radius_m())
    goal = goal_in_world(target, ik.chain.base_placement)
    from_joint = float(np.linalg.norm(goal.position - ik.reach.center))
    assert refused.from_first_joint_m == pytest.approx(from_joint)
    assert refused.distance_m == pytest.approx(from_joint - refused.reach_m)
    what = "point" if point else "pose"
    assert re.fullmatch(
        rf"{what} unreachable: the target is \d+\.\d{{3}} m from the arm's first joint, which "
        rf"reaches \d+\.\d{{3}} m at most: every tool {what} is at least \d+\.\d mm away, over the "
        r"0\.1 mm tolerance",
        str(refused),
    ), str(refused)


# --- point targets (orientation free) --------------------------------------------------


@pytest.mark.parametrize("name", ALL_ARMS)
def test_point_targets_from_random_seeds(name: str) -> None:
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(77)
    solved = 0
    for _ in range(100):
        target = PointTarget.at(robot.ee_pose(robot.random(rng)).translation)
        try:
            q = ik.solve(target, robot.random(rng))
        except Unreachable:
            continue
        solved += 1
        assert point_error(robot, q, target) <= PROMISE_M
        assert within_limits(robot, q)
    assert solved >= 99, f"{name}: {solved}/100 points"


@pytest.mark.parametrize("name", BUNDLED)
def test_a_near_point_keeps_the_arm_near_its_seed(name: str) -> None:
    """Orientation free, the steps are of least joint motion: the arm barely moves."""
    ik = solver(name)
    robot = ik.robot
    rng = np.random.default_rng(6)
    moves = []
    for _ in range(20):
        seed = np.array(robot.random(rng))
        nudged = robot.ee_pose(seed.tolist()).translation + rng.uniform(-0.005, 0.005, 3)
        q = ik.solve(PointTarget.at(nudged), seed.tolist())
        moves.append(float(np.abs(np.subtract(q, seed)).max()))
    # 5 mm is a few hundredths of a radian, more near a singularity; never another branch
    assert max(moves) < 0.5 and sorted(moves)[-3] < 0.1, moves


def test_a_point_with_a_tool_offset() -> None:
    ik = solver("kuka_lwr")
    robot = ik.robot
    tool = pin.SE3(np.eye(3), np.array([0.0, 0.05, 0.2]))
    rng = np.random.default_rng(8)
    for _ in range(20):
        point = PointTarget.at((robot.ee_pose(robot.random(rng)) * tool).translation)
        q = ik.solve(point, robot.random(rng), tool)
        assert np.linalg.norm((robot.ee_pose(q) * tool).translation - point.position) <= 1e-4


def test_an_unreachable_point_says_how_far_the_closest_point_is() -> None:
    ik = solver("fanuc_lrmate200id")
    robot = ik.robot
    under = PointTarget.at((0.0, 0.0, -0.3))  # inside the reach bound, under the base
    with pytest.raises(Unreachable) as caught:
        ik.solve(under, robot.home)
    refused = caught.value
    assert refused.orientation_free and refused.reach_m is None and refused.angle_rad == 0.0
    match = re.fullmatch(
        r"point unreachable: the closest reachable tool point is (\d+\.\d) mm away, "
        r"over the 0\.1 mm tolerance",
        str(refused),
    )
    assert match is not None, str(refused)
    assert float(match[1]) == round(refused.distance_m * 1e3, 1)
    rng = np.random.default_rng(0)
    sampled = min(point_error(robot, tuple(robot.random(rng)), under) for _ in range(4000))
    assert PROMISE_M < refused.distance_m <= sampled


@pytest.mark.parametrize(
    ("xyz", "problem"),
    [((1.0, 2.0), "three finite numbers"), ((1.0, math.nan, 0.0), "three finite numbers")],
)
def test_a_point_needs_three_finite_numbers(xyz: tuple[float, ...], problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        PointTarget.at(xyz)


# --- refusals state the tolerance they miss --------------------------------------------


@pytest.mark.parametrize(
    ("distance_m", "angle_deg", "text"),
    [
        (0.25, 28.6, "250.0 mm and 28.6 deg away"),
        (1.04e-4, 0.0, "0.104 mm and 0.0 deg away"),  # not "0.1 mm": that reads as reached
        (0.0, 0.1004, "0.0 mm and 0.1004 deg away"),
        (2e-5, 45.0, "0.0 mm and 45.0 deg away"),
    ],
)
def test_a_refusal_states_the_tolerance_it_missed(
    distance_m: float, angle_deg: float, text: str
) -> None:
    refused = Unreachable(distance_m, math.radians(angle_deg))
    assert str(refused) == (
        f"pose unreachable: the closest reachable tool pose is {text}, "
        "over the 0.1 mm / 0.1 deg tolerance"
    )


# --- straight lines to a point ---------------------------------------------------------


@pytest.mark.parametrize("name", BUNDLED)
def test_a_line_to_a_point(name: str) -> None:
    """The tool point keeps to the segment; the orientation is free (and drifts little)."""
    ik = solver(name)
    robot = ik.robot
    q0 = list(BENT_ELBOW[name])
    start = ik.tool_pose(q0)
    goal = PointTarget.at(start.translation + np.array([0.08, -0.06, 0.05]))
    line = plan_line(ik, q0, goal)
    waypoints = line.waypoints
    assert waypoints[0].q == tuple(q0) and waypoints[-1].s == 1.0
    for a, b in zip(waypoints, waypoints[1:]):
        step = robot.ee_pose(b.q).translation - robot.ee_pose(a.q).translation
        assert np.linalg.norm(step) <= 0.005 + 2e-4
    for waypoint in waypoints:
        on_line = start.translation + waypoint.s * (np.array(goal.position) - start.translation)
        assert np.linalg.norm(robot.ee_pose(waypoint.q).translation - on_line) <= 1e-4
        assert within_limits(robot, waypoint.q)
    assert point_error(robot, waypoints[-1].q, goal) <= 1e-9
    np.testing.assert_allclose(line.goal.translation, goal.position, atol=1e-9)
    assert line.angle_rad < math.radians(30)


def test_a_five_joint_arm_follows_a_line_to_a_point_not_to_a_pose() -> None:
    """so100 (5 joints) cannot hold its orientation along a line, but can keep its tool
    point on one: issue 30's 'nearly every movel is unreachable' on small arms."""
    ik = solver("so100")
    robot = ik.robot
    assert robot.n == 5
    q0 = [0.2, -0.8, 0.9, 0.6, 0.3]
    start = ik.tool_pose(q0)
    end = start.translation + np.array([0.03, 0.02, -0.02])
    with pytest.raises(Unreachable):  # 3 cm away with the same orientation: not for 5 joints
        plan_line(ik, q0, pin.SE3(start.rotation, end))
    line = plan_line(ik, q0, PointTarget.at(end))
    assert line.waypoints[-1].s == 1.0
    assert point_error(robot, line.waypoints[-1].q, PointTarget.at(end)) <= 1e-9


# --- a pose sent reads back as sent ----------------------------------------------------


@pytest.mark.parametrize(
    "sent",
    [
        (0.6, 0.2, 1.0, 0.0, 90.0, 0.0),  # issue 30: once read back as 30.64,89.99997,30.64
        (0.6, -0.2, 1.0, 0.0, 90.0, 0.0),
        (0.5, 0.1, 0.7, 180.0, 0.0, 0.0),  # tool down
        (0.4, 0.3, 0.9, 0.0, 150.0, 0.0),  # not 180,30,180
        (0.5, 0.0, 0.6, 0.0, 180.0, 0.0),  # not 180,0,180
        (0.45, -0.25, 0.8, 12.5, -33.25, 101.75),
    ],
    ids=str,
)
def test_a_pose_sent_reads_back_as_sent(sent: tuple[float, ...]) -> None:
    """moveto x,y,z,r,p,y then pose: the solution is exact to rounding and canonical_rpy
    reads its orientation back in the form it was sent (10 significant digits agree)."""
    ik = solver("motoman_sia20d")
    robot = ik.robot
    tool = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1]))
    x, y, z, *rpy_deg = sent
    target = pin.SE3(pin.rpy.rpyToMatrix(*np.radians(rpy_deg)), np.array([x, y, z]))
    q = ik.solve(target, robot.home, tool)
    pose = robot.ee_pose(q) * tool
    read = [*pose.translation, *np.degrees(canonical_rpy(pose.rotation))]
    np.testing.assert_allclose(read, sent, rtol=0, atol=1e-9)
