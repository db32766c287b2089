"""The batched check a CollisionModel hands out (``batch_check``): the same answers as the
model, other robots as obstacles, pairs left out or kept alone; and pairs between robots."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot

from c2rviz.collision import CollisionModel, pairs_between, placed_shapes
from c2rviz.collision.batch import CHUNK

ROBOTS = ["motoman_sia20d", "fanuc_lrmate200id", "kuka_lwr"]


def at(x: float, y: float, z: float) -> pin.SE3:
    return pin.SE3(np.eye(3), np.array([x, y, z]))


@pytest.mark.parametrize("name", ROBOTS)
def test_the_batched_check_answers_as_the_model(name: str) -> None:
    robot = load_robot(name)
    model = CollisionModel(robot)
    model.set_object("crate", "box", (0.3, 0.3, 0.3), at(0.5, 0.2, 0.6))
    model.set_object("ball", "sphere", (0.15,), at(-0.4, 0.0, 0.9))
    check = model.batch_check()
    rng = np.random.default_rng(4)
    qs = np.array([robot.random(rng) for _ in range(5 * CHUNK + 3)])
    expected = [model.colliding(q) for q in qs]
    assert [check.colliding(q) for q in qs] == expected
    assert [check.is_valid(q) for q in qs] == [not pairs for pairs in expected]
    assert list(check.hits(qs)) == [bool(pairs) for pairs in expected]
    first = next((k for k, pairs in enumerate(expected) if pairs), None)
    assert check.first_invalid(qs) == first and any(expected) and not all(expected)
    free = [q for q, pairs in zip(qs, expected) if not pairs]
    assert check.first_invalid(np.array(free)) is None


def test_a_snapshot_keeps_what_it_was_built_with() -> None:
    model = CollisionModel(load_robot("kuka_lwr"))
    before = model.check_geometry()
    check = model.batch_check()
    model.set_object("crate", "box", (0.3, 0.3, 0.3), at(0.0, 0.0, 0.8))
    assert model.revision == before.revision + 1 == model.check_geometry().revision
    q = [0.0] * 7  # the arm straight up: through the crate
    assert model.colliding(q) and check.colliding(q) == []


def test_pairs_may_be_left_out_or_kept_alone() -> None:
    robot = load_robot("motoman_sia20d")
    model = CollisionModel(robot)
    model.set_object("wall", "box", (0.2, 0.2, 0.2), at(0.0, 0.8, 0.85))
    q = np.radians([90, 60, 0, 0, 0, 0, 0])
    pairs = model.colliding(q)
    assert len(pairs) == 3
    assert model.batch_check(without=pairs[:2]).colliding(q) == pairs[2:]
    only = model.batch_check(only=pairs[1:2])
    assert only.colliding(q) == pairs[1:2] and set(only.names) == set(pairs[1:2])
    assert model.batch_check(only=[]).is_valid(q)


def test_other_robots_are_obstacles_and_pairs_between_name_both() -> None:
    robot = load_robot("motoman_sia20d")
    a, b = CollisionModel(robot), CollisionModel(robot)
    here, there = at(0, -0.45, 0), at(0, 0.45, 0)
    towards = np.radians([90, 90, 0, 0, 0, 0, 0])  # a's arm held out level towards b
    home = [0.0] * 7
    others = [("b", b, home, there)]
    found = pairs_between(a, here, towards, others)
    assert found and all(
        mine.startswith("link_") and theirs.startswith("b/") for mine, theirs in found
    )
    assert pairs_between(a, here, home, others) == []
    check = a.batch_check(placed_shapes("b", b, home, there), origin=here)
    assert check.colliding(towards) == found
    assert check.is_valid(home)
