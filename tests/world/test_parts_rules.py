"""The parts' rules without a server: the model's checks, the drop, the grasp rule on a
made-up gripper, and a hand-over between two robots of a cell."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot

from c2rviz.collision.geometry import drop, extent
from c2rviz.collision.other_robots import placed_shapes
from c2rviz.collision.workcell import collision_geometry, make_object
from c2rviz.robot.gripper import Gripper
from c2rviz.world.part_rules import Goal, Jaws, opening_for, score, take
from c2rviz.world.parts import PartError, Parts, TooManyParts, UnknownPart
from c2rviz.world.world import World

PICK = (0, 0.3, -0.3, 0, -0.9707963, 0)  # the fanuc pointing straight down (see test_part_verbs)
JAWS = np.array([0.4438, 0.0, 0.339])


def _at(x: float, y: float, z: float, yaw: float = 0.0) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(0, 0, yaw), np.array([x, y, z]))


def _gripper() -> Gripper:
    """Jaws 0 apart closed, 60 mm open, in a straight line."""
    return Gripper("hand", ("f",), (0,), (0.0,), (1.0,), 1.0, (0.0, 0.06))


def test_the_model_refuses_duplicates_too_many_and_bad_sizes() -> None:
    parts = Parts(max_parts=1)
    parts.add(parts.make("a", "box", (0.1, 0.1, 0.1), _at(0, 0, 0.05)))
    with pytest.raises(PartError, match="'a' is already a part"):
        parts.make("a", "sphere", (0.1,), _at(1, 0, 0.1))
    with pytest.raises(TooManyParts):
        parts.make("b", "sphere", (0.1,), _at(1, 0, 0.1))
    with pytest.raises(PartError, match="outside 0.001..2 m"):
        Parts().make("c", "sphere", (1e308,), _at(1, 0, 0.1))
    with pytest.raises(PartError, match="an object's or a link's"):
        Parts().make("table", "sphere", (0.1,), _at(1, 0, 0.1), taken=("table",))
    with pytest.raises(UnknownPart, match=r"no part named 'z' \(parts: a\)"):
        parts.get("z")


def test_extent_across_a_turned_box_and_a_lying_cylinder() -> None:
    turned = pin.rpy.rpyToMatrix(0, 0, math.pi / 4)
    assert extent("box", (0.1, 0.1, 0.1), turned, np.array([1.0, 0, 0])) == pytest.approx(
        0.1 * math.sqrt(2) / 2
    )
    lying = pin.rpy.rpyToMatrix(0, math.pi / 2, 0)
    assert extent("cylinder", (0.02, 0.2), lying, np.array([1.0, 0, 0])) == pytest.approx(0.1)
    assert extent("cylinder", (0.02, 0.2), lying, np.array([0, 0, 1.0])) == pytest.approx(0.02)


def test_a_part_drops_onto_the_first_surface_below() -> None:
    table = make_object("table", "box", (0.4, 0.4, 0.1), _at(0, 0, 0.05))
    obstacles = [("table", collision_geometry(table), table.placement)]
    part = make_object("p", "box", (0.05, 0.05, 0.05), _at(0.1, 0, 0.5))
    geometry = collision_geometry(part)
    down, onto = drop("box", part.size, geometry, part.placement, obstacles)
    assert onto == "table" and down == pytest.approx(0.5 - 0.025 - 0.1, abs=1e-4)
    beside = _at(0.3, 0, 0.5)  # its edge 5 mm past the table's
    down, onto = drop("box", part.size, geometry, beside, obstacles)
    assert onto == "floor" and down == pytest.approx(0.475)
    inside = _at(0.1, 0, 0.08)  # put into the table: passed by, down to the floor
    assert drop("box", part.size, geometry, inside, obstacles) == (pytest.approx(0.055), "floor")


def test_the_grasp_rule_on_a_made_up_gripper() -> None:
    gripper = _gripper()
    jaws = Jaws(np.zeros(3), np.array([0.0, 1.0, 0.0]), 0.06)
    parts = Parts()

    def part(name: str, width: float, y: float = 0.0, z: float = 0.0):
        made = parts.make(name, "box", (width, width, 0.1), _at(0, y, z))
        return made

    cube = part("cube", 0.03)
    assert take(jaws, gripper, 0.0, [cube]) is cube
    assert opening_for(gripper, 0.03) == pytest.approx(0.5)
    assert take(jaws, gripper, 0.6, [cube]) is None  # 36 mm apart: not touching
    assert take(jaws, gripper, 0.0, [part("wide", 0.07)]) is None
    assert take(jaws, gripper, 0.0, [part("beside", 0.03, y=0.05)]) is None
    assert take(jaws, gripper, 0.0, [part("above", 0.03, z=0.06)]) is None  # line misses it
    assert take(jaws, gripper, 0.0, [part("edge", 0.03, y=0.016)]) is not None  # 1 mm out
    shut = Jaws(np.zeros(3), np.array([0.0, 1.0, 0.0]), 0.0)
    assert take(shut, gripper, 0.0, [cube]) is None


def test_score_pairs_type_goals_with_the_nearest_part_of_their_type() -> None:
    parts = Parts()
    a = parts.make("a", "sphere", (0.01,), _at(0, 0, 0.01), kind="ball")
    b = parts.make("b", "sphere", (0.01,), _at(1, 0, 0.01), kind="ball")
    goals = [
        Goal("type=ball", _at(1, 0, 0.01)),
        Goal("type=ball", _at(0.002, 0, 0.01)),  # b is taken: a, 2 mm off
        Goal("type=cube", _at(0, 0, 0)),
    ]
    results = score(goals, [a, b])
    assert [(r.part, r.met) for r in results] == [("b", True), ("a", True), (None, False)]


def _cell() -> World:
    fanuc = load_robot("fanuc_lrmate200id")
    # b stands so that its jaws at PICK meet a's, turned a quarter turn about the vertical
    turn = pin.SE3(pin.rpy.rpyToMatrix(0, 0, math.pi / 2), np.zeros(3))
    origin = pin.SE3(np.eye(3), JAWS) * turn * pin.SE3(np.eye(3), -JAWS)
    world = World({"a": fanuc, "b": fanuc}, origins={"b": origin})
    for name in ("a", "b"):
        world.set_q(PICK, name)
        world.state(name).opening = 1.0
    return world


def test_a_hand_over_between_two_robots_of_a_cell() -> None:
    asyncio.run(_hand_over())  # a loop: the released part falls on the world's clock


async def _hand_over() -> None:
    world = _cell()
    parts = world.parts
    parts.add("p", "box", (0.03, 0.03, 0.03), _at(*JAWS))
    opening, taken = parts.close("a", 1.0, 0.0)
    assert taken is not None and taken.holder == "a" and opening == pytest.approx(0.5, abs=0.01)
    world.state("a").opening = opening
    opening, taken = parts.close("b", 1.0, 0.0)  # b closes across a's fingers: b has it now
    assert taken is not None and taken.holder == "b"
    assert parts.parts.held_by("a") == []
    assert parts.release("a") == []  # a opening lets go of nothing
    world.set_q((0.3, *PICK[1:]), "b")  # b turns away with it
    moved = parts.parts.get("p").pose.translation
    assert np.linalg.norm(moved - JAWS) > 0.05
    assert [p.name for p in parts.release("b")] == ["p"]
    assert parts.parts.get("p").holder is None
    world.close()


def test_a_held_part_collides_with_another_robot_of_the_cell() -> None:
    asyncio.run(_held_against_the_other())


async def _held_against_the_other() -> None:
    world = _cell()
    world.parts.add("p", "box", (0.03, 0.03, 0.03), _at(*JAWS))
    _, taken = world.parts.close("a", 1.0, 0.0)
    assert taken is not None
    # (the two hands overlap: a rule test, not a cell one could build)
    assert ("p", "b/gripper_hand") not in world.contacts.now("a")
    # b's fingers (checked closed, through p) may touch the part a holds, as a's may
    fingers = {"gripper_finger_left", "gripper_finger_right"}
    assert not [(x, y) for x, y in world.contacts.now("a") if x == "p" and y[2:] in fingers]
    assert not [(x, y) for x, y in world.contacts.now("b") if x in fingers and y == "a/p"]
    source = world.collision_model("b").check_geometry()
    others = placed_shapes("a", world.collision_model("a"), world.state("a").q, pin.SE3.Identity())
    check = world.collision_model("b").batch_check(others, origin=world.state("b").origin)
    assert not [n for n in check.names if n[0] in fingers and n[1] == "a/p"]
    assert [n for n in check.names if n == ("gripper_hand", "a/p")]
    assert source.touch == fingers and "p" in source.parts
    world.set_q((0, 0.32, -0.33, 0, -0.9207963, 0), "b")  # b's hand 17 mm lower: onto p
    assert ("p", "b/gripper_hand") in world.contacts.now("a")
    assert ("gripper_hand", "a/p") in world.contacts.now("b")
    world.close()
