"""Tests of the pick-and-place controller, as its author writes them: a c2rviz server per
test (the ``c2rviz`` fixture is a client connected to it), on virtual time (pytest.ini).
"""

from __future__ import annotations

import pytest
from controller import FEEDER, TABLE, above, pick_and_place, set_up, slot

from c2rviz import CommandError, Event
from c2rviz.testing import assert_arrives, assert_no_collision_during

CYCLE_S = 15.0
"""Longest time a part may take, feeder to tray [s]."""


def test_every_part_is_placed_in_its_slot(c2rviz):
    set_up(c2rviz)
    with c2rviz.watch() as stream:
        pick_and_place(c2rviz, parts=3)
        c2rviz.sleep(0)  # its reply comes after every event so far
        markers = []
        for record in stream:
            if isinstance(record, Event) and record.kind == "marker":
                markers.append(tuple(float(v) for v in record.detail.split()[0].split(",")))
            if len(markers) == 6:
                break
    placed = markers[1::2]  # a part at the feeder, then where it went
    for index, pose in enumerate(placed):
        assert pose[:3] == pytest.approx(slot(index)[:3], abs=1e-4)


def test_the_arm_never_touches_the_table(c2rviz):
    set_up(c2rviz)
    with assert_no_collision_during(c2rviz):
        pick_and_place(c2rviz, parts=2)


def test_a_cycle_takes_at_most_cycle_s(c2rviz, c2rviz_server):
    set_up(c2rviz)
    start = c2rviz_server.now()
    pick_and_place(c2rviz, parts=4)
    per_part = (c2rviz_server.now() - start) / 4
    assert per_part <= CYCLE_S, f"{per_part:.1f} s a part"


def test_the_approach_arrives_where_it_should(c2rviz):
    set_up(c2rviz)
    c2rviz.motion("follow")  # answered at once: assert_arrives waits for the arrival
    goal = c2rviz.ik(above(FEEDER))
    c2rviz.moveto(above(FEEDER))
    assert_arrives(c2rviz, within=5.0, at=goal)


def test_with_the_table_in_the_way_the_guard_refuses_the_move(c2rviz):
    set_up(c2rviz)
    name, shape, size, pose = TABLE
    c2rviz.add_object(name, shape, size, (pose[0], pose[1], 0.47, 0, 0, 0))  # raised 7 cm
    with pytest.raises(CommandError, match="table"):
        pick_and_place(c2rviz, parts=1)
    assert c2rviz.collisions() == []  # refused before anything moved into it
