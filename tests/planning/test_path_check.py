"""The guard's path check: the first point that blocks, and contacts at the start left."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from planning_scenes import load

from c2rviz.collision import CollisionModel, placed_shapes
from c2rviz.errors import PathCollides
from c2rviz.planning import (
    MoveChecker,
    MoveRequest,
    ValidityChecker,
    edge_resolution,
    first_blocked,
    path_points,
)


def checker() -> ValidityChecker:
    model = CollisionModel(load("motoman_sia20d"))
    model.set_object("wall", "box", (0.2, 0.2, 0.2), pin.SE3(np.eye(3), np.array([0, 0.8, 0.85])))
    return ValidityChecker(model)


def deg(*values: float) -> np.ndarray:
    return np.radians(values)


def test_the_first_blocked_point_in_order() -> None:
    valid = checker()
    points = path_points(
        valid, np.array([deg(-90, 60, 0, 0, 0, 0, 0), deg(180, 60, 0, 0, 0, 0, 0)])
    )
    assert np.max(np.abs(np.diff(points, axis=0))) <= np.radians(1.0) + 1e-12
    index, pair = first_blocked(valid, points)
    assert pair[1] == "wall" and 0.5 < index / (len(points) - 1) < 0.8
    assert valid.is_valid(points[index - 1]) and not valid.is_valid(points[index])
    assert first_blocked(valid, points[:index]) is None


def test_a_contact_at_the_start_may_be_left_but_not_pushed_into_or_met_again() -> None:
    valid = checker()
    inside = deg(90, 60, 0, 0, 0, 0, 0)
    allowed = valid.batch.colliding(inside)
    assert len(allowed) == 3
    leave = path_points(valid, np.array([inside, deg(0, 60, 0, 0, 0, 0, 0)]))
    assert first_blocked(valid, leave) == (0, allowed[0])  # without leave: blocked at once
    assert first_blocked(valid, leave, allowed) is None
    turn = path_points(valid, np.array([inside, deg(90, 60, 0, 0, 0, 0, 90)]))
    assert first_blocked(valid, turn, allowed) is None  # stays in, no new pair
    bend = path_points(valid, np.array([inside, deg(90, 60, 0, 0, 0, -90, 90)]))
    index, pair = first_blocked(valid, bend, allowed)
    assert pair == ("link_t", "wall") and index > 0
    through = path_points(valid, np.array([inside, deg(0, 60, 0, 0, 0, 0, 0), inside]))
    index, pair = first_blocked(valid, through, allowed)  # out and back in: blocked again
    assert pair in allowed and index > len(through) // 2


def test_the_move_checker_follows_the_other_robots_where_they_are() -> None:
    """Its kept checker is rebuilt when another robot stands elsewhere (moving or not)."""
    robot = load("motoman_sia20d")
    a, b = CollisionModel(robot), CollisionModel(robot)
    here, there = (
        pin.SE3(np.eye(3), np.array([0, -0.45, 0])),
        pin.SE3(np.eye(3), np.array([0, 0.45, 0])),
    )
    towards_a = deg(-90, 60, 0, 0, 0, 0, 0)  # b's arm held out towards a, over a's head
    goal = np.zeros(7)  # a upright
    moves = MoveChecker()
    answers = []
    for q_b in (np.zeros(7), towards_a):
        request = MoveRequest(
            a,
            a.check_geometry(),
            tuple(placed_shapes("b", b, q_b, there)),
            (("b", None, there.homogeneous.tobytes()),),  # b moving: same key either way
            here,
            edge_resolution(robot),
            tuple(deg(0, 60, 0, 0, 0, 0, 0)),  # a held out along +x: free of b either way
            (tuple(goal),),
            target_only=True,
        )
        try:
            moves.check(request)
            answers.append("free")
        except PathCollides as exc:
            answers.append(exc.pair[1].split("/")[0])
    assert answers == ["free", "b"]
