"""A small pick-and-place controller for c2rviz: real parts from a table into a kit tray,
and what it does when something goes wrong.

The cell (docs/parts.md): the bundled ``fanuc_lrmate200id`` and its parallel gripper, a
table in front of it, three cubes (parts ``p1``..``p3``) in a row on the table's left,
a kit tray on its right, each of its slots a goal (``goal pN ...``), and a logical camera
``top`` above the table looking down (docs/cameras.md). For each part the controller
finds it with the camera, goes above it, straight down until the part lies between the
open fingers, closes them (``grip 0``: by the grasp rule they stop on the part, and the
part moves with the gripper), lifts it, carries it above its slot, goes down, opens the
fingers (the part rests on the tray) and goes up again. It runs with the guard on, so a
move that would sweep the arm or a carried part through the table or the tray is refused
before the arm moves; ``score`` then says every goal is met.

It recovers, as a cell's controller must (docs/faults.md):

- **a dropped part**: after each move of the carry it asks the gripper whether it still
  holds the part (``part NAME``'s state, as a gripper's part-present signal); if not,
  it lets the part land, opens the fingers, finds the part with the camera where it fell,
  picks it again and carries it on;
- **a protective stop**: a move refused by one waits ``STOP_WAIT_S`` (a UR cannot be
  unlocked sooner), ``reset``s and is sent again; a move still refused after
  ``RESETS`` resets, and an emergency stop, are left to a person: they raise;
- **a camera blackout**: a camera that does not see the part is read again every
  ``LOOK_AGAIN_S`` until it does, for at most ``LOOK_FOR_S``.

Each recovery is logged (``logging``, the logger ``pick_and_place``).

Run it against a running server (``c2rviz --robot fanuc_lrmate200id``, then in another
terminal)::

    python examples/pick_and_place/controller.py --parts 3

Its tests (``test_controller.py`` beside it) run it against a server of their own, on
virtual time, faults included: ``pytest examples/pick_and_place``.
"""

from __future__ import annotations

import argparse
import logging
import math
import sys
from collections.abc import Callable, Sequence
from typing import TypeVar

from scipy.spatial.transform import Rotation

from c2rviz import Client, CommandError, Pose

log = logging.getLogger("pick_and_place")
T = TypeVar("T")

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
CAMERA = ("top", (0.45, 0.0, 1.2, 0.0, math.pi / 2, 0.0))
"""The logical camera: name, pose [m, rad] in the world frame, 1 m above the table and
looking straight down; its default view (60 by 45 degrees, 2 m) takes in the whole table."""
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
LOOK_AGAIN_S = 0.5
"""A camera that does not see the part is read again after this long [s]."""
LOOK_FOR_S = 10.0
"""... for at most this long [s]: then the part is lost."""
STOP_WAIT_S = 5.0
"""A protective stop is reset this long after a move was refused [s]."""
RESETS = 3
"""At most this many resets for one move: a stop that keeps coming back needs a person."""
SETTLE_S = 1.0
"""A dropped part has landed this long after the drop was noticed [s] (it falls at g)."""
REGRASPS = 3
"""A dropped part is picked again at most this many times: then the controller gives up."""


def tool_at(part: Sequence[float], lift_m: float = 0.0) -> Pose:
    """The tool pose that has the part centre at ``part`` between the fingers, the fingers
    turned with the part's yaw, raised by ``lift_m`` [m]."""
    roll, pitch, _ = DOWN
    return Pose(part[0], part[1], part[2] + JAWS_M + lift_m, roll, pitch, part[5])


def in_world(camera: Sequence[float], seen: Sequence[float]) -> tuple[float, ...]:
    """A pose the camera at ``camera`` reports (its frame) in the world frame [m, rad]."""
    turn = Rotation.from_euler("xyz", camera[3:])  # roll, pitch, yaw: about fixed axes
    x, y, z = turn.apply(seen[:3]) + camera[:3]
    roll, pitch, yaw = (turn * Rotation.from_euler("xyz", seen[3:])).as_euler("xyz")
    return (float(x), float(y), float(z), float(roll), float(pitch), float(yaw))


def move(robot: Client, command: Callable[..., T], *args: object) -> T:
    """``command(*args)`` (a move or ``grip``), waiting out protective stops: refused by
    one, wait ``STOP_WAIT_S``, ``reset`` and send it again.

    Raises:
        CommandError: any other refusal (an emergency stop, a collision ahead), or still
            refused after ``RESETS`` resets.
    """
    for _ in range(RESETS):
        try:
            return command(*args)
        except CommandError as error:
            if not error.message.startswith("protective stop"):
                raise
            log.warning("%s; reset in %g s", error.message, STOP_WAIT_S)
            robot.sleep(STOP_WAIT_S)
            robot.reset()
    return command(*args)  # refused again: a person must see to it


def set_up(robot: Client, parts: int = len(PARTS)) -> None:
    """Radians, moves that answer on arrival, the table, the tray, the camera, the first
    ``parts`` parts on the table and their goals in the tray, the gripper open, the guard
    on."""
    robot.radians()
    robot.motion("on")
    robot.speed(SPEED)
    robot.lspeed(LINE_SPEED_M_S)
    objects = robot.objects()
    for name, shape, size, pose in (TABLE, TRAY):
        if name not in objects:
            robot.add_object(name, shape, size, pose)
    robot.add_camera(*CAMERA)
    there = robot.parts()
    for name in list(PARTS)[:parts]:
        if name not in there:
            robot.add_part(name, "box", (PART_M,) * 3, PARTS[name], kind="cube", color=(1, 0.5, 0))
        robot.goal(name, SLOTS[name])
    move(robot, robot.grip, 1.0)
    robot.guard(True)


def locate(robot: Client, name: str) -> tuple[float, ...]:
    """Where part ``name`` is, world frame [m, rad], as the camera sees it; read again
    every ``LOOK_AGAIN_S`` while it does not see it (a blackout, a part still falling).

    Raises:
        RuntimeError: the camera did not see it for ``LOOK_FOR_S``.
    """
    camera, pose = CAMERA
    for look in range(round(LOOK_FOR_S / LOOK_AGAIN_S) + 1):
        if look == 1:
            log.warning("camera %s does not see %s: looking again", camera, name)
        if look:
            robot.sleep(LOOK_AGAIN_S)
        for seen in robot.camera(camera):
            if seen.name == name:
                return in_world(pose, seen.pose)
    raise RuntimeError(f"camera {camera} has not seen {name} for {LOOK_FOR_S:g} s")


def holds(robot: Client, name: str) -> bool:
    """Whether the gripper holds part ``name`` (its part-present signal)."""
    return robot.part(name).state == "held"


def pick(robot: Client, name: str) -> None:
    """Take part ``name`` from where the camera sees it: above it, down, close, up.

    Raises:
        RuntimeError: the fingers closed on nothing (the part was not between them).
    """
    where = locate(robot, name)
    move(robot, robot.moveto, tool_at(where, CLEARANCE_M))
    move(robot, robot.movel, tool_at(where))
    move(robot, robot.grip, 0.0)  # the fingers stop on the part: the grasp rule
    if not holds(robot, name):
        raise RuntimeError(f"{name} was not grasped: {robot.part(name)}")
    move(robot, robot.movel, tool_at(where, CLEARANCE_M))


def place(robot: Client, name: str, slot: Sequence[float]) -> bool:
    """Put part ``name``, held, down on ``slot``: above it, down, open, up. Returns False
    when the gripper lost it on the way (the arm stops where it noticed)."""
    move(robot, robot.moveto, tool_at(slot, CLEARANCE_M))
    if not holds(robot, name):
        return False
    move(robot, robot.movel, tool_at(slot, PLACE_GAP_M))
    if not holds(robot, name):
        return False
    move(robot, robot.grip, 1.0)  # released: it rests on the tray
    move(robot, robot.movel, tool_at(slot, CLEARANCE_M))
    return True


def deliver(robot: Client, name: str) -> None:
    """Pick part ``name`` and place it in its slot, picking it again where it fell when
    the gripper drops it on the way.

    Raises:
        RuntimeError: it was dropped more than ``REGRASPS`` times.
    """
    for _ in range(REGRASPS + 1):
        pick(robot, name)
        if place(robot, name, SLOTS[name]):
            return
        log.warning("%s dropped on the way: picking it again where it fell", name)
        robot.sleep(SETTLE_S)  # let it land
        move(robot, robot.grip, 1.0)  # after a drop the fingers stay where they were
    raise RuntimeError(f"{name} was dropped {REGRASPS + 1} times")


def pick_and_place(robot: Client, parts: int = len(PARTS)) -> None:
    """Move the first ``parts`` parts into their slots; every call returns on arrival.

    Raises:
        CommandError: a move was refused (it would collide, or is out of reach; an
            emergency stop): the arm stays where the last move left it.
        RuntimeError: a part was lost (not grasped, not seen, dropped again and again).
    """
    for name in list(PARTS)[:parts]:
        deliver(robot, name)
    move(robot, robot.home)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Pick the parts into the kit tray.")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=31000)
    parser.add_argument("--parts", type=int, choices=range(1, len(PARTS) + 1), default=3)
    args = parser.parse_args(argv)
    logging.basicConfig(format="%(name)s: %(message)s")  # recoveries, on stderr
    with Client(args.host, args.port) as robot:
        set_up(robot, args.parts)
        pick_and_place(robot, args.parts)
        score = robot.score()
    print(f"placed {args.parts} parts: {score.met}/{score.total} goals met")
    return 0 if score.met == score.total else 1


if __name__ == "__main__":
    sys.exit(main())
