"""A small pick-and-place controller for c2rviz: parts from a feeder to a tray.

The cell: a table in front of the robot, a feeder on its left where parts come, a tray
on its right where they go. A part is a marker (the server draws it; the Motoman has no
gripper, so "holding" a part is moving the tool to it and dropping a marker where it is
placed). For each part the controller goes above the feeder, straight down to the part,
up, across above the tray, down, places the part (a green marker), and up again; it
refuses to start if the cell's table is missing, and it runs with the guard on, so a
move that would hit the table is refused before the arm moves.

Run it against a running server (``c2rviz``, then in another terminal)::

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

DOWN = (math.pi, 0.0, 0.0)
"""The tool pointing down: roll, pitch, yaw [rad]."""
FEEDER = Pose(0.6, 0.3, 0.45, *DOWN)
"""Where a part is picked [m, rad], in the robot's base frame."""
TRAY = Pose(0.6, -0.3, 0.45, *DOWN)
"""Where the first part is placed; the next ones go ``PITCH_M`` further along x."""
PITCH_M = 0.05
"""Distance between placed parts [m]."""
CLEARANCE_M = 0.10
"""How far above a part the tool travels between the feeder and the tray [m]."""
TABLE = ("table", "box", (0.8, 1.2, 0.05), (0.7, 0.0, 0.375, 0.0, 0.0, 0.0))
"""The cell's table: name, shape, size [m], pose [m, rad]: its top is at z = 0.4 m."""
SPEED = 60.0
"""Joint moves at this % of the limits."""
LINE_SPEED_M_S = 0.2
"""Straight approaches at this tool speed [m/s]."""


def above(pose: Pose, height_m: float = CLEARANCE_M) -> Pose:
    """``pose`` raised by ``height_m`` [m]."""
    return pose._replace(z=pose.z + height_m)


def slot(index: int) -> Pose:
    """Where part ``index`` (from 0) is placed in the tray."""
    return TRAY._replace(x=TRAY.x + index * PITCH_M)


def set_up(robot: Client) -> None:
    """Radians, moves that answer on arrival, the guard on, the cell's table there."""
    robot.radians()
    robot.motion("on")
    robot.speed(SPEED)
    robot.lspeed(LINE_SPEED_M_S)
    name, shape, size, pose = TABLE
    if name not in robot.objects():
        robot.add_object(name, shape, size, pose)
    robot.guard(True)


def pick_and_place(robot: Client, parts: int) -> None:
    """Move ``parts`` parts from the feeder to the tray; every call returns on arrival.

    Raises:
        CommandError: a move was refused (it would collide, or is out of reach): the arm
            stays where the last move left it.
    """
    for index in range(parts):
        robot.color(1.0, 0.5, 0.0)
        robot.mark(FEEDER)  # the part waiting at the feeder
        robot.moveto(above(FEEDER))
        robot.movel(FEEDER)  # straight down onto it
        robot.movel(above(FEEDER))  # and up with it
        target = slot(index)
        robot.moveto(above(target))
        robot.movel(target)
        robot.color(0.0, 0.8, 0.0)
        robot.mark()  # placed: a part where the tool is
        robot.movel(above(target))
    robot.home()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Pick parts from the feeder to the tray.")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=31000)
    parser.add_argument("--parts", type=int, default=3)
    args = parser.parse_args(argv)
    with Client(args.host, args.port) as robot:
        set_up(robot)
        pick_and_place(robot, args.parts)
    print(f"placed {args.parts} parts")
    return 0


if __name__ == "__main__":
    sys.exit(main())
