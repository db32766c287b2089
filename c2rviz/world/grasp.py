"""The grasp rule: when closing fingers (or a suction cup) take a part. Pure, no state.

Parallel gripper. The *jaws* are the finger links' collision shapes: their centre is
the midpoint of the first two fingers' shapes (the middle of each shape's bounding box)
at the opening shown now, and the *closing axis* runs from one to the other (at the
gripper's full opening). The *gap* is the gripper's separation now (the one CRCL reports).
Closing to opening S takes a part when all of these hold (of several, the one whose
centre is nearest the closing line):

- the closing line (the axis through the jaws' centre) passes through the part, at the
  point of it nearest the part's centre (a long part may be held by one end);
- the part fits between the fingers as they are now: its width across the axis is at most
  the gap plus ``GRIP_TOL_M``, and it lies within the gap (± ``GRIP_TOL_M``);
- the fingers would pass its width: the separation at S is below it.

The fingers then stop where they touch it (the opening whose separation is its width) and
the part is moved along the axis to the jaws' centre (the closing fingers centre it).

Vacuum gripper: the tool point is the cup; suction on takes the nearest part whose
surface is within ``CUP_M`` of it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from ..collision.geometry import contains, extent, signed_distance
from ..robot.gripper import FINGER_WORD, Gripper
from ..robot.model import Robot
from .parts import Part

__all__ = [
    "SUCTION_BELOW",
    "VACUUM_STROKE_S",
    "is_vacuum",
    "make_vacuum",
    "CUP_M",
    "GRIP_TOL_M",
    "Jaws",
    "at_cup",
    "extent",
    "finger_links",
    "jaws",
    "opening_for",
    "take",
]

GRIP_TOL_M = 0.002
"""How far a part may stand out of the gap between the fingers and still be taken [m]."""
CUP_M = 0.003
"""A vacuum cup takes a part whose surface is at most this far from it [m]."""


SUCTION_BELOW = 0.5
"""A vacuum gripper's suction is on below this opening (``grip 0``), off from it (``grip 1``)."""
VACUUM_STROKE_S = 0.05
"""Suction on to off, or back [s]."""


def make_vacuum(link: str) -> Gripper:
    """A vacuum gripper: no finger joints, its cup the robot's tool point on ``link``."""
    return Gripper(link, (), (), (), (), VACUUM_STROKE_S)


def is_vacuum(gripper: Gripper | None) -> bool:
    """True for a vacuum gripper (one with no finger joints)."""
    return gripper is not None and not gripper.joints


@dataclass(frozen=True)
class Jaws:
    """Where a parallel gripper's fingers are, in the world frame.

    Attributes:
        centre: The midpoint between the fingers [m].
        axis: Unit vector from one finger to the other.
        gap: The separation between them now [m].
    """

    centre: np.ndarray
    axis: np.ndarray
    gap: float


def finger_joints(robot: Robot) -> list[int]:
    """The joint ids of the fingers: off the chain, named for fingers or by the ini's
    gripper, in model order."""
    gripper = robot.gripper
    named = set(gripper.joints) if gripper is not None else set()
    model = robot.model
    return [
        j
        for j in range(1, model.njoints)
        if model.names[j] not in robot.joint_names
        and (FINGER_WORD in model.names[j].lower() or model.names[j] in named)
    ]


def finger_links(robot: Robot) -> frozenset[str]:
    """The links the finger joints move (they may touch parts)."""
    joints = set(finger_joints(robot))
    return frozenset(
        frame.name
        for frame in robot.model.frames
        if frame.type == pin.FrameType.BODY and frame.parentJoint in joints
    )


def _pads(
    robot: Robot, geometry: pin.GeometryModel, q: Sequence[float], opening: float
) -> list[np.ndarray]:
    """The centre of each finger's shapes in the model's root frame, finger by finger."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, robot.configuration(q, opening))
    centres: list[np.ndarray] = []
    for joint in finger_joints(robot):
        points = []
        for obj in geometry.geometryObjects:
            if obj.parentJoint != joint:
                continue
            if obj.geometry.aabb_radius <= 0:
                obj.geometry.computeLocalAABB()
            placement = data.oMi[joint] * obj.placement
            points.append(placement.act(np.asarray(obj.geometry.aabb_center)))
        if points:
            centres.append(np.mean(points, axis=0))
    return centres


def jaws(
    robot: Robot,
    geometry: pin.GeometryModel,
    origin: pin.SE3,
    q: Sequence[float],
    opening: float,
) -> Jaws | None:
    """The jaws of ``robot`` (its root at ``origin``) at chain values ``q`` and ``opening``;
    None if it has no gripper or its fingers have no shapes."""
    gripper = robot.gripper
    if gripper is None:
        return None
    now = _pads(robot, geometry, q, opening)
    wide = _pads(robot, geometry, q, 1.0)
    if len(now) >= 2:
        centre = (now[0] + now[1]) / 2.0
        axis = wide[0] - wide[1]
    elif len(now) == 1:
        shut = _pads(robot, geometry, q, 0.0)
        centre = (now[0] + shut[0]) / 2.0
        axis = wide[0] - shut[0]
    else:
        return None
    norm = float(np.linalg.norm(axis))
    if norm < 1e-9:
        return None
    axis_world = origin.rotation @ (axis / norm)
    return Jaws(origin.act(centre), axis_world, gripper.separation(opening))


def opening_for(gripper: Gripper, separation: float) -> float:
    """The opening (0..1) at which the jaws' separation is ``separation`` [m]: the largest
    found whose separation is still below it (so closing to it again touches the part:
    a replay of a recorded ``grip`` grasps as the run did)."""
    low, high = 0.0, 1.0
    if gripper.separation(high) <= separation:
        return high
    for _ in range(40):
        middle = (low + high) / 2.0
        if gripper.separation(middle) < separation:
            low = middle
        else:
            high = middle
    return low


def take(jaws: Jaws, gripper: Gripper, target: float, parts: Sequence[Part]) -> Part | None:
    """The part that closing to opening ``target`` takes, by the rule (module), if any."""
    best: tuple[float, Part] | None = None
    for part in parts:
        offset = part.pose.translation - jaws.centre
        along = float(offset @ jaws.axis)
        across = float(np.linalg.norm(offset - along * jaws.axis))
        if not contains(part.obj.shape, part.obj.size, part.pose, jaws.centre + along * jaws.axis):
            continue
        half = extent(part.obj.shape, part.obj.size, part.pose.rotation, jaws.axis)
        if 2.0 * half > jaws.gap + GRIP_TOL_M or abs(along) + half > jaws.gap / 2.0 + GRIP_TOL_M:
            continue
        if gripper.separation(target) >= 2.0 * half:
            continue
        if best is None or across < best[0]:
            best = (across, part)
    return None if best is None else best[1]


def at_cup(cup: pin.SE3, parts: Sequence[Part]) -> Part | None:
    """The part whose surface is nearest the cup (the tool point, in the world), if
    within ``CUP_M``."""
    point = coal.Sphere(1e-6)
    best: tuple[float, Part] | None = None
    for part in parts:
        distance = signed_distance(point, cup, part.geometry, part.pose)
        if distance <= CUP_M and (best is None or distance < best[0]):
            best = (distance, part)
    return None if best is None else best[1]
