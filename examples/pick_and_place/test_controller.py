"""Tests of the pick-and-place controller, as its author writes them: a c2rviz server per
test (the ``c2rviz`` fixture is a client connected to it) with the fanuc and its gripper,
on virtual time, the outcome checked where the parts ended (``assert_goals_met``,
``assert_part_at``).

The recoveries are tested with faults (docs/faults.md) the test schedules on the server's
clock once the cell is set up (``c2rviz.fault(..., after=S)``), so each one comes at the
same point of the job every run: ``CARRY_S`` after the set-up the arm carries ``p1``
halfway to its slot.
"""

from __future__ import annotations

import pytest
from controller import (
    CAMERA,
    LOOK_FOR_S,
    PART_M,
    PARTS,
    ROBOT,
    SLOTS,
    STOP_WAIT_S,
    TRAY,
    pick,
    pick_and_place,
    set_up,
)

from c2rviz import CommandError
from c2rviz.testing import assert_goals_met, assert_no_collision_during, assert_part_at

pytestmark = pytest.mark.c2rviz(robot=ROBOT, clock="virtual")

CYCLE_S = 15.0
"""Longest time a part may take, table to tray [s]."""
CARRY_S = 5.2
"""When the arm carries ``p1`` from the table to the tray: this long after ``set_up`` [s]
(the carry runs from 4.6 to 5.8 s)."""


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


def test_a_part_lying_turned_is_grasped_square_and_placed_straight(c2rviz):
    set_up(c2rviz, parts=1)
    turned = (*PARTS["p1"][:5], 0.4)  # turned 0.4 rad about the vertical: as a drop leaves it
    c2rviz.remove_part("p1")
    c2rviz.add_part("p1", "box", (PART_M,) * 3, turned)
    pick_and_place(c2rviz, parts=1)  # the camera sees it turned: the fingers turn with it
    assert_goals_met(c2rviz)


def test_with_the_tray_raised_the_guard_refuses_to_sweep_the_part_through_it(c2rviz):
    set_up(c2rviz, parts=1)
    name, shape, size, pose = TRAY
    c2rviz.remove_object(name)
    c2rviz.add_object(name, shape, (size[0], size[1], 0.07), (pose[0], pose[1], 0.235, 0, 0, 0))
    with pytest.raises(CommandError, match="tray"):
        pick_and_place(c2rviz, parts=1)
    assert c2rviz.part("p1").state == "held"  # refused before anything moved into the tray
    assert c2rviz.collisions() == []


def test_a_part_dropped_on_the_way_is_picked_again_where_it_fell(c2rviz, caplog):
    set_up(c2rviz, parts=2)
    c2rviz.fault("drop", after=CARRY_S)  # the gripper lets p1 go halfway to the tray
    pick_and_place(c2rviz, parts=2)
    assert "p1 dropped on the way: picking it again where it fell" in caplog.messages
    assert c2rviz.faults() == []  # the drop came due
    assert_goals_met(c2rviz)


def test_a_protective_stop_is_waited_out_and_reset(c2rviz, c2rviz_server, caplog):
    set_up(c2rviz, parts=2)
    start = c2rviz_server.now()
    c2rviz.fault("protective", after=CARRY_S)  # the arm brakes with p1 in the gripper
    pick_and_place(c2rviz, parts=2)
    stopped = f"protective stop since t={start + CARRY_S:.3f} (reset to move again)"
    assert f"{stopped}; reset in {STOP_WAIT_S:g} s" in caplog.messages
    assert c2rviz.faults() == []  # reset
    assert_goals_met(c2rviz)
    assert not any("dropped" in message for message in caplog.messages)


@pytest.mark.c2rviz(faults=["protective"])  # the cell starts in a protective stop
def test_a_cell_that_starts_stopped_is_reset_once_the_wait_is_over(c2rviz, caplog):
    set_up(c2rviz, parts=1)
    assert caplog.messages == [
        f"protective stop since t=0.000 (reset to move again); reset in {STOP_WAIT_S:g} s"
    ]
    pick_and_place(c2rviz, parts=1)
    assert_goals_met(c2rviz)


def test_an_emergency_stop_is_left_to_a_person(c2rviz):
    set_up(c2rviz, parts=1)
    c2rviz.fault("estop", after=CARRY_S)
    with pytest.raises(CommandError, match="emergency stop since"):
        pick_and_place(c2rviz, parts=1)
    assert c2rviz.faults()[0].startswith("estop since")  # not reset by the controller
    assert c2rviz.part("p1").state == "held"  # stopped with it, halfway


def test_a_camera_blackout_is_read_through(c2rviz, caplog):
    set_up(c2rviz, parts=2)
    c2rviz.fault("blackout", CAMERA[0], 2)  # the camera sees nothing for 2 s
    assert c2rviz.camera(CAMERA[0]) == []
    pick_and_place(c2rviz, parts=2)
    assert "camera top does not see p1: looking again" in caplog.messages
    assert_goals_met(c2rviz)


def test_a_camera_dark_for_good_loses_the_part(c2rviz, c2rviz_server):
    set_up(c2rviz, parts=1)
    c2rviz.fault("blackout", CAMERA[0])  # until cleared
    start = c2rviz_server.now()
    with pytest.raises(RuntimeError, match=f"camera top has not seen p1 for {LOOK_FOR_S:g} s"):
        pick_and_place(c2rviz, parts=1)
    assert c2rviz_server.now() - start == pytest.approx(LOOK_FOR_S)
    assert_part_at(c2rviz, "p1", PARTS["p1"])  # untouched, on the table
