"""The planner's checks answer as the collision model does; edges are cut finely enough."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from planning_scenes import BUNDLED, ROOT, erd_folder, load

from c2rviz.collision import CollisionModel
from c2rviz.planning import (
    BadPlanningSetting,
    EdgeResolution,
    ValidityChecker,
    edge_resolution,
    lever_arms,
    plan_for,
    robot_shapes,
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


def near_contacts(model: CollisionModel, count: int, seed: int) -> list[np.ndarray]:
    """Pairs of configurations 1e-9 apart on either side of a contact (bisection)."""
    robot = model.robot
    rng = np.random.default_rng(seed)
    found: list[np.ndarray] = []
    while len(found) < 2 * count:
        a, b = np.array(robot.random(rng)), np.array(robot.random(rng))
        free_a = model.is_free(list(a))
        if free_a == model.is_free(list(b)):
            continue
        for _ in range(32):
            middle = (a + b) / 2
            if model.is_free(list(middle)) == free_a:
                a = middle
            else:
                b = middle
        found += [a, b]
    return found


@pytest.mark.parametrize("name", ARMS)
def test_checker_answers_as_the_collision_model_at_contact(name: str) -> None:
    model = CollisionModel(load(name))
    model.set_object("box", "box", (0.3, 0.3, 0.3), pin.SE3(np.eye(3), np.array([0.45, 0.1, 0.4])))
    checker = ValidityChecker(model)
    qs = near_contacts(model, 40, seed=3)
    expected = [model.is_free(list(q)) for q in qs]
    assert True in expected and False in expected
    assert [checker.is_valid(q) for q in qs] == expected
    assert [checker.describe(q) for q in qs] == [
        None if free else model.colliding(list(q))[0] for q, free in zip(qs, expected)
    ]
    first = checker.first_invalid(np.array(qs))
    assert first == expected.index(False)
    # asked again, in another order: the answers do not depend on what came before
    assert [checker.is_valid(q) for q in reversed(qs)] == expected[::-1]


def test_other_robots_are_obstacles_named_by_robot_and_link() -> None:
    robot = load("fanuc_lrmate200id")
    mine, theirs = CollisionModel(robot), CollisionModel(load("kuka_lwr"))
    there = pin.SE3(pin.rpy.rpyToMatrix(0, 0, math.pi), np.array([0.7, 0.0, 0.0]))
    others = robot_shapes("kuka", theirs, [0.0] * 7, there)  # upright, 0.7 m in front
    assert others[0][0].startswith("kuka/")
    reach = [0.0, 0.8, 0.0, 0.0, 0.0, 0.0]  # the Fanuc leans forward, into the kuka
    alone, cell = ValidityChecker(mine), ValidityChecker(mine, others)
    assert alone.is_valid(reach) and cell.is_valid([0.0] * 6)
    assert not cell.is_valid(reach)
    link, other = cell.describe(reach) or ("", "")
    assert link in robot.link_names() and other.startswith("kuka/lwr_")
    # the other robot moved 3 m away (this robot's origin is where the kuka's is not)
    far = ValidityChecker(mine, others, origin=pin.SE3(np.eye(3), np.array([-3.0, 0, 0])))
    assert far.is_valid(reach)


@pytest.mark.parametrize("name", ARMS)
def test_lever_arms_bound_the_tool_speed_per_joint(name: str) -> None:
    robot = load(name)
    arms = lever_arms(robot)
    model, data = robot.model, robot.model.createData()
    columns = [model.joints[model.getJointId(joint.name)].idx_v for joint in robot.joints]
    rng = np.random.default_rng(5)
    for _ in range(300):
        config = robot.configuration(robot.random(rng))
        jacobian = pin.computeFrameJacobian(
            model, data, config, robot.ee_frame, pin.LOCAL_WORLD_ALIGNED
        )
        speeds = np.linalg.norm(jacobian[:3, columns], axis=0)  # tool [m/s] per joint [rad/s]
        assert np.all(speeds <= np.array(arms) + 1e-9)


@pytest.mark.parametrize("name", ARMS)
def test_edge_points_keep_joint_and_tool_steps(name: str) -> None:
    robot = load(name)
    checker = ValidityChecker(CollisionModel(robot))
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(8)

    def tool(q: np.ndarray) -> np.ndarray:
        pin.framesForwardKinematics(model, data, robot.configuration(list(q)))
        return data.oMf[robot.ee_frame].translation.copy()

    for _ in range(20):
        a, b = np.array(robot.random(rng)), np.array(robot.random(rng))
        b = a + 0.4 * (b - a)
        points = checker.edge_points(a, b)
        assert np.allclose(points[0], a) and np.allclose(points[-1], b)
        steps = np.abs(np.diff(points, axis=0))
        assert np.max(steps) <= math.radians(1.0) + 1e-12
        # the tool's travel between checked points, measured along the way by dense FK
        for p, r in zip(points[:-1], points[1:]):
            dense = [tool(p + f * (r - p)) for f in np.linspace(0, 1, 9)]
            travel = sum(np.linalg.norm(y - x) for x, y in zip(dense[:-1], dense[1:]))
            assert travel <= 0.005 + 1e-9


def test_check_edge_refuses_a_blocked_edge_quickly_and_counts() -> None:
    model = CollisionModel(load("kuka_lwr"))
    checker = ValidityChecker(model)
    a = np.zeros(7)
    b = np.array([0.0, 1.4, 0.0, 0.0, 0.0, 0.0, 0.0])
    free, count = checker.check_edge(a, b)
    assert free and count == len(checker.edge_points(a, b)) - 1
    middle = load("kuka_lwr").ee_pose([0.0, 0.7, 0, 0, 0, 0, 0]).translation
    model.set_object("box", "box", (0.1, 0.1, 0.1), pin.SE3(np.eye(3), middle))
    checker = ValidityChecker(model)
    free, count = checker.check_edge(a, b)
    assert not free and count < 10  # far end, middle, quarters...


@pytest.mark.parametrize(
    ("kwargs", "key"),
    [
        ({"max_step_rad": math.nan}, "max_step_rad"),
        ({"max_step_rad": 0.0}, "max_step_rad"),
        ({"max_step_rad": -0.01}, "max_step_rad"),
        ({"max_step_rad": 3.0}, "max_step_rad"),
        ({"max_step_m": math.inf}, "max_step_m"),
        ({"max_tool_step_m": 0.0}, "max_tool_step_m"),
        ({"max_tool_step_m": 1e9}, "max_tool_step_m"),
        ({"max_tool_step_m": "5"}, "max_tool_step_m"),
    ],
    ids=lambda x: str(x),
)
def test_bad_resolutions_are_refused_with_the_range(kwargs: dict, key: str) -> None:
    with pytest.raises(BadPlanningSetting, match=rf"^{key} = .* is not valid: give a number from"):
        edge_resolution(load("kuka_lwr"), **kwargs)


def test_resolution_without_tool_bound_is_the_joint_grid() -> None:
    resolution = EdgeResolution((0.01, 0.02))
    grid = resolution.grid([0.0, 0.0], [0.1, -0.1])
    assert len(grid) == 11 and np.allclose(grid[-1], [0.1, -0.1])
    with pytest.raises(BadPlanningSetting, match="lever_arm"):
        EdgeResolution((0.01, 0.02), 0.005, (1.0,))


def test_a_continuous_joint_plans_to_its_literal_value() -> None:
    robot = Robot.from_urdf(ROOT / "tests/data/limits_robot/limits.urdf")
    assert robot.joints[2].continuous
    checker = ValidityChecker(CollisionModel(robot))
    qs = np.array([[0.1, -0.2, 7.0], [0.0, 0.3, -2.5]])
    assert np.allclose(checker.configurations(qs).T, [robot.configuration(q) for q in qs])
    lower, upper = checker.bounds([0.0, 0.0, 7.0], [0.0, 0.0, -1.0])
    assert lower[2] == pytest.approx(-1.0 - math.pi) and upper[2] == pytest.approx(7.0 + math.pi)
    assert lower[:2] == robot.lower[:2] and upper[:2] == robot.upper[:2]
    path = plan_for(checker, [0.0, 0.0, 0.0], [0.5, 0.3, 7.0])
    assert path.waypoints.tolist() == [[0.0, 0.0, 0.0], [0.5, 0.3, 7.0]]  # no wrapping
