"""A small pick-and-place controller for c2rviz: real parts from a table into a kit tray.

The cell (docs/parts.md): the bundled ``fanuc_lrmate200id`` and its parallel gripper, a
table in front of it, three cubes (parts ``p1``..``p3``) in a row on the table's left,
and a kit tray on its right, each of its slots a goal (``goal pN ...``). For each part
the controller goes above it, straight down until the part lies between the open
fingers, closes them (``grip 0``: by the grasp rule they stop on the part, and the part
moves with the gripper), lifts it, carries it above its slot, goes down, opens the
fingers (the part rests on the tray) and goes up again. It runs with the guard on, so
a move that would sweep the arm or a carried part through the table or the tray is
refused before the arm moves; ``score`` then says every goal is met.

Run it against a running server (``c2rviz --robot fanuc_lrmate200id``, then in another
terminal)::

    python examples/pick_and_place/controller.py --parts 3

Its tests (``test_controller.py`` beside it) run it against a server of their own, on
virtual time: ``pytest examples/pick_and_place``.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from c2rviz import Client, Pose

ROBOT = "fanuc_lrmate200id"
"""The arm this cell is laid out for (it has a gripper: 60 mm between open fingers)."""
DOWN = (0.0, math.pi / 2, 0.0)
"""The fanuc's tool (its flange normal) pointing down: roll, pitch, yaw [rad]."""
JAWS_M = 0.08
"""How far below the tool point the part's centre is when the fingers can close on it [m]."""
CLEARANCE_M = 0.10
"""How far above the pick and place poses the tool travels between them [m]."""
PART_M = 0.03
"""Each part is a cube this wide [m] (the open fingers are 60 mm apart)."""
TABLE = ("table", "box", (0.5, 0.8, 0.05), (0.45, 0.0, 0.175, 0.0, 0.0, 0.0))
"""The cell's table: name, shape, size [m], pose [m, rad]: its top is at z = 0.2 m."""
TRAY = ("tray", "box", (0.2, 0.12, 0.01), (0.45, -0.2, 0.205, 0.0, 0.0, 0.0))
"""The kit tray on the table: its top is at z = 0.21 m."""
PARTS = {
    "p1": (0.40, 0.2, 0.2 + PART_M / 2, 0.0, 0.0, 0.0),
    "p2": (0.45, 0.2, 0.2 + PART_M / 2, 0.0, 0.0, 0.0),
    "p3": (0.50, 0.2, 0.2 + PART_M / 2, 0.0, 0.0, 0.0),
}
"""Where each part waits on the table [m, rad]."""
SLOTS = {
    "p1": (0.40, -0.2, 0.21 + PART_M / 2, 0.0, 0.0, 0.0),
    "p2": (0.45, -0.2, 0.21 + PART_M / 2, 0.0, 0.0, 0.0),
    "p3": (0.50, -0.2, 0.21 + PART_M / 2, 0.0, 0.0, 0.0),
}
"""The kit: where each part should end, on the tray [m, rad] (its goal)."""
PLACE_GAP_M = 0.001
"""A part is let go this far above its slot: it settles onto the tray (docs/parts.md)."""
SPEED = 60.0
"""Joint moves at this % of the limits."""
LINE_SPEED_M_S = 0.2
"""Straight approaches at this tool speed [m/s]."""


def tool_at(part: Sequence[float], lift_m: float = 0.0) -> Pose:
    """The tool pose that has the part centre at ``part`` between the fingers, raised by
    ``lift_m`` [m]."""
    return Pose(part[0], part[1], part[2] + JAWS_M + lift_m, *DOWN)


def set_up(robot: Client, parts: int = len(PARTS)) -> None:
    """Radians, moves that answer on arrival, the table, the tray, the first ``parts``
    parts on the table and their goals in the tray, the gripper open, the guard on."""
    robot.radians()
    robot.motion("on")
    robot.speed(SPEED)
    robot.lspeed(LINE_SPEED_M_S)
    objects = robot.objects()
    for name, shape, size, pose in (TABLE, TRAY):
        if name not in objects:
            robot.add_object(name, shape, size, pose)
    there = robot.parts()
    for name in list(PARTS)[:parts]:
        if name not in there:
            robot.add_part(name, "box", (PART_M,) * 3, PARTS[name], kind="cube", color=(1, 0.5, 0))
        robot.goal(name, SLOTS[name])
    robot.grip(1.0)
    robot.guard(True)


def pick(robot: Client, name: str) -> None:
    """Take part ``name`` from where it lies: above it, down, close, up with it.

    Raises:
        RuntimeError: the fingers closed on nothing (the part was not between them).
    """
    where = robot.part(name).pose
    robot.moveto(tool_at(where, CLEARANCE_M))
    robot.movel(tool_at(where))
    robot.grip(0.0)  # the fingers stop on the part: the grasp rule
    if robot.part(name).state != "held":
        raise RuntimeError(f"{name} was not grasped: {robot.part(name)}")
    robot.movel(tool_at(where, CLEARANCE_M))


def place(robot: Client, slot: Sequence[float]) -> None:
    """Put the part held down on ``slot``: above it, down, open, up."""
    robot.moveto(tool_at(slot, CLEARANCE_M))
    robot.movel(tool_at(slot, PLACE_GAP_M))
    robot.grip(1.0)  # released: it rests on the tray
    robot.movel(tool_at(slot, CLEARANCE_M))


def pick_and_place(robot: Client, parts: int = len(PARTS)) -> None:
    """Move the first ``parts`` parts into their slots; every call returns on arrival.

    Raises:
        CommandError: a move was refused (it would collide, or is out of reach): the arm
            stays where the last move left it.
    """
    for name in list(PARTS)[:parts]:
        pick(robot, name)
        place(robot, SLOTS[name])
    robot.home()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Pick the parts into the kit tray.")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=31000)
    parser.add_argument("--parts", type=int, choices=range(1, len(PARTS) + 1), default=3)
    args = parser.parse_args(argv)
    with Client(args.host, args.port) as robot:
        set_up(robot, args.parts)
        pick_and_place(robot, args.parts)
        score = robot.score()
    print(f"placed {args.parts} parts: {score.met}/{score.total} goals met")
    return 0 if score.met == score.total else 1


if __name__ == "__main__":
    sys.exit(main())
