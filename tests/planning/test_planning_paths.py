"""Planned paths go around boxes (an independent Pinocchio + coal check says so), and in time."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from planning_scenes import (
    BUNDLED,
    IndependentCheck,
    blocked_scenes,
    erd_folder,
    furnish,
    load,
    polyline_samples,
)

from c2rviz.collision import CollisionModel
from c2rviz.errors import C2rvizError
from c2rviz.motion import motion_limits
from c2rviz.planning import (
    BadPlanningSetting,
    GoalCollides,
    NoPathFound,
    OutOfLimits,
    StartCollides,
    ValidityChecker,
    plan_for,
    plan_path,
    time_path,
)
from c2rviz.robot import Robot

ARMS = [
    *BUNDLED,
    pytest.param(
        "panda",
        marks=pytest.mark.skipif(
            erd_folder() is None, reason="example-robot-data is not installed"
        ),
    ),
]
FINE_RAD = math.radians(0.2)  # [rad] independent samples of a path: 5 per planner step
DT = 4e-3  # [s] samples of the timed motion


@pytest.mark.parametrize("name", ARMS)
def test_paths_around_boxes_are_free_within_limits_and_arrive(name: str) -> None:
    robot = load(name)
    model = CollisionModel(robot)
    limits = motion_limits(robot)
    low, high = np.array(robot.lower), np.array(robot.upper)
    for k, scene in enumerate(blocked_scenes(model, 2, seed=21)):
        furnish(model, scene)
        check = IndependentCheck(name, scene)
        straight = polyline_samples(np.array([scene.start, scene.goal]), FINE_RAD)
        assert any(check.hits(q) for q in straight), "the box must be in the way"
        path = plan_for(ValidityChecker(model), scene.start, scene.goal, timeout_s=10.0, seed=k)
        waypoints = path.waypoints
        assert len(waypoints) >= 3  # it went around
        assert tuple(waypoints[0]) == scene.start and tuple(waypoints[-1]) == scene.goal
        assert np.all(waypoints >= low) and np.all(waypoints <= high)
        length = np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))
        assert path.length_rad == pytest.approx(length)
        for q in polyline_samples(waypoints, FINE_RAD):
            assert check.hits(q) == [], f"scene {k}: {check.hits(q)} at {q}"
        timed = time_path(waypoints, limits, start=0.0, speed=1.0)
        times = np.arange(0.0, timed.arrival + DT, DT)
        qs = np.array([timed.sample(t) for t in times])
        assert np.all(qs >= low) and np.all(qs <= high)
        for q in qs:
            assert check.hits(q) == [], f"scene {k}: the timed motion touches {check.hits(q)}"
        velocity = np.diff(qs, axis=0) / DT
        acceleration = np.diff(velocity, axis=0) / DT
        assert np.all(np.abs(velocity) <= np.array(limits.velocity) * (1 + 1e-6))
        bound = np.array(limits.acceleration) + np.array(limits.jerk) * DT
        assert np.all(np.abs(acceleration) <= bound * (1 + 1e-6))
        assert timed.sample(timed.arrival) == scene.goal


def test_the_same_seed_gives_the_same_path_whatever_ran_before() -> None:
    model = CollisionModel(load("kuka_lwr"))
    scene, other = blocked_scenes(model, 2, seed=5)
    furnish(model, scene)
    first = plan_for(ValidityChecker(model), scene.start, scene.goal, seed=123)
    furnish(model, other)
    plan_for(ValidityChecker(model), other.start, other.goal, seed=7)  # something in between
    furnish(model, scene)
    again = plan_for(ValidityChecker(model), scene.start, scene.goal, seed=123)
    assert np.array_equal(first.waypoints, again.waypoints)
    assert first.states_checked == again.states_checked and again.seed == 123
    unseeded = plan_for(ValidityChecker(model), scene.start, scene.goal)
    replay = plan_for(ValidityChecker(model), scene.start, scene.goal, seed=unseeded.seed)
    assert np.array_equal(unseeded.waypoints, replay.waypoints)


def test_a_free_straight_path_is_the_path() -> None:
    model = CollisionModel(load("fanuc_lrmate200id"))
    path = plan_for(ValidityChecker(model), [0.0] * 6, [0.5, 0.2, -0.2, 0.3, 0.1, 1.0])
    assert path.waypoints.shape == (2, 6) and path.states_checked > 100


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


def test_a_hand_behind_a_plate_with_a_rod_sized_hole_finds_no_path(tmp_path: Path) -> None:
    """The hand went through a wall's 8 cm hole on its rod; it cannot come back."""
    urdf = tmp_path / "trap.urdf"
    urdf.write_text(TRAP_URDF)
    robot = Robot.from_urdf(urdf, "base", "hand")
    model = CollisionModel(robot)
    hole, wall = 0.04, (0.55, 0.57)  # [m] half the hole's side; the wall's x extent
    x, depth = sum(wall) / 2, wall[1] - wall[0]
    height = 0.1  # the rod's height at the goal
    for name, size, centre in [
        ("below", (depth, 4.0, 2.0), (x, 0.0, height - hole - 1.0)),
        ("above", (depth, 4.0, 2.0), (x, 0.0, height + hole + 1.0)),
        ("left", (depth, 2.0, 2 * hole), (x, hole + 1.0, height)),
        ("right", (depth, 2.0, 2 * hole), (x, -hole - 1.0, height)),
    ]:
        model.set_object(name, "box", size, pin.SE3(np.eye(3), np.array(centre)))
    start, goal = [3.0, 0.0, 0.0], [0.0, 0.0, 0.0]  # hand behind the robot; hand past the wall
    checker = ValidityChecker(model)
    assert checker.is_valid(start) and checker.is_valid(goal)
    with pytest.raises(NoPathFound) as caught:
        plan_for(checker, start, goal, timeout_s=0.3, seed=1)
    assert re.fullmatch(r"no path found in 0\.3 s \(\d+ states\)", str(caught.value))
    assert caught.value.states > 1000 and caught.value.timeout_s == 0.3
    # without the wall's top half the hand goes over it
    model.remove_object("above")
    path = plan_for(ValidityChecker(model), start, goal, timeout_s=5.0, seed=1)
    assert len(path.waypoints) >= 3


def test_a_goal_enclosed_in_a_box_shell_in_joint_space_finds_no_path() -> None:
    """Two joints, the goal inside a square shell of invalid states: no way in."""

    def in_shell(q: np.ndarray) -> bool:
        d = np.max(np.abs(np.asarray(q) - 1.0))
        return 0.2 <= d <= 0.3  # the shell around (1, 1)

    def is_valid(q: np.ndarray) -> bool:
        return not in_shell(q)

    with pytest.raises(NoPathFound, match=r"^no path found in 0\.2 s \(\d+ states\)$"):
        plan_path(
            [-1, -1], [1, 1], [-2, -2], [2, 2], is_valid, max_step=[0.01, 0.01], timeout_s=0.2
        )

    # a wall with a gap: the path goes through the gap, every point of it valid
    def wall(q: np.ndarray) -> bool:
        return not (abs(q[0]) <= 0.05 and q[1] < 1.5)

    path = plan_path([-1, -1], [1, -1], [-2, -2], [2, 2], wall, max_step=[0.01, 0.01], seed=3)
    dense = polyline_samples(path.waypoints, 0.002)
    assert all(wall(q) for q in dense)
    assert max(q[1] for q in dense) > 1.5


@pytest.fixture(scope="module")
def boxed() -> tuple[CollisionModel, list[float], list[float]]:
    """The kuka with a box where its tool is at ``inside``; ``free`` is clear of it."""
    robot = load("kuka_lwr")
    model = CollisionModel(robot)
    inside = [0.0, 0.8, 0.0, -0.6, 0.0, 0.5, 0.0]
    where = robot.ee_pose(inside).translation
    model.set_object("crate", "box", (0.2, 0.2, 0.2), pin.SE3(np.eye(3), where))
    return model, inside, [0.0] * 7


def test_ends_that_collide_name_the_pair(boxed: tuple[CollisionModel, list, list]) -> None:
    model, inside, free = boxed
    checker = ValidityChecker(model)
    with pytest.raises(StartCollides, match=r"^the start collides: lwr_\w+ touches crate "):
        plan_for(checker, inside, free)
    with pytest.raises(GoalCollides, match=r"^the goal collides: lwr_\w+ would touch crate$"):
        plan_for(checker, free, inside)


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        ({"goal": [0.0, 3.0, 0, 0, 0, 0, 0]}, OutOfLimits, r"^the goal's joint 1 = 3 is outside"),
        ({"start": [math.nan] * 7}, OutOfLimits, r"^the start's joint 0 = nan is outside"),
        ({"timeout_s": math.nan}, BadPlanningSetting, r"^timeout_s = nan is not valid"),
        ({"timeout_s": 0.0}, BadPlanningSetting, r"^timeout_s = 0\.0 is not valid: give a"),
        ({"timeout_s": -1}, BadPlanningSetting, r"^timeout_s = -1 is not valid"),
        ({"timeout_s": 1e9}, BadPlanningSetting, r"^timeout_s = 1000000000\.0 is not valid"),
        ({"seed": -1}, BadPlanningSetting, r"^seed = -1 is not valid: give a whole number"),
        ({"seed": 1.5}, BadPlanningSetting, r"^seed = 1\.5 is not valid"),
        ({"goal": [0.0] * 6}, BadPlanningSetting, r"^goal = .* give 7 values"),
    ],
    ids=[
        "goal limit",
        "start nan",
        "nan timeout",
        "zero timeout",
        "negative",
        "huge",
        "seed",
        "seed float",
        "goal length",
    ],  # fmt: skip
)
def test_bad_requests_are_refused_clearly(
    boxed: tuple[CollisionModel, list, list], change: dict, error: type, message: str
) -> None:
    model, _, free = boxed
    request = {"start": free, "goal": [0.3] * 7, "timeout_s": 1.0, "seed": 1} | change
    with pytest.raises(error, match=message) as caught:
        plan_for(ValidityChecker(model), **request)
    assert isinstance(caught.value, C2rvizError) and "\n" not in str(caught.value)


def test_plan_path_takes_max_step_or_check_edge_not_both() -> None:
    with pytest.raises(BadPlanningSetting, match="give max_step or check_edge"):
        plan_path([0.0], [1.0], [-1.0], [2.0], lambda q: True)
    with pytest.raises(BadPlanningSetting, match=r"^max_step = "):
        plan_path([0.0], [1.0], [-1.0], [2.0], lambda q: True, max_step=[math.inf])
    with pytest.raises(BadPlanningSetting, match=r"^max_step = .* give 1 values"):
        plan_path([0.0], [1.0], [-1.0], [2.0], lambda q: True, max_step=[0.1, 0.1])
