"""Tests of the pick-and-place controller, as its author writes them: a c2rviz server per
test (the ``c2rviz`` fixture is a client connected to it) with the fanuc and its gripper,
on virtual time, the outcome checked where the parts ended (``assert_goals_met``,
``assert_part_at``).
"""

from __future__ import annotations

import pytest
from controller import PARTS, ROBOT, SLOTS, TRAY, pick, pick_and_place, set_up

from c2rviz import CommandError
from c2rviz.testing import assert_goals_met, assert_no_collision_during, assert_part_at

pytestmark = pytest.mark.c2rviz(robot=ROBOT, clock="virtual")

CYCLE_S = 15.0
"""Longest time a part may take, table to tray [s]."""


def test_every_part_ends_in_its_slot(c2rviz):
    set_up(c2rviz)
    pick_and_place(c2rviz)
    assert_goals_met(c2rviz)
    for name, slot in SLOTS.items():
        assert_part_at(c2rviz, name, slot, tol=0.001, tol_angle=0.01)
        assert c2rviz.part(name).state == "resting on tray"


def test_the_arm_and_the_parts_never_touch_the_table(c2rviz):
    set_up(c2rviz, parts=2)
    with assert_no_collision_during(c2rviz):
        pick_and_place(c2rviz, parts=2)
    assert_goals_met(c2rviz)


def test_a_cycle_takes_at_most_cycle_s(c2rviz, c2rviz_server):
    set_up(c2rviz)
    start = c2rviz_server.now()
    pick_and_place(c2rviz)
    per_part = (c2rviz_server.now() - start) / len(PARTS)
    assert per_part <= CYCLE_S, f"{per_part:.1f} s a part"


def test_a_part_not_where_it_was_said_is_not_grasped(c2rviz):
    set_up(c2rviz, parts=1)
    c2rviz.grip(0.0)  # fingers closed already: nothing between them can be taken
    with pytest.raises(RuntimeError, match="p1 was not grasped"):
        pick(c2rviz, "p1")
    assert_part_at(c2rviz, "p1", PARTS["p1"])  # untouched, on the table


def test_with_the_tray_raised_the_guard_refuses_to_sweep_the_part_through_it(c2rviz):
    set_up(c2rviz, parts=1)
    name, shape, size, pose = TRAY
    c2rviz.remove_object(name)
    c2rviz.add_object(name, shape, (size[0], size[1], 0.07), (pose[0], pose[1], 0.235, 0, 0, 0))
    with pytest.raises(CommandError, match="tray"):
        pick_and_place(c2rviz, parts=1)
    assert c2rviz.part("p1").state == "held"  # refused before anything moved into the tray
    assert c2rviz.collisions() == []
