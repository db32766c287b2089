"""The rules of parts, pure: the grasp rule (what closing fingers or a suction cup take) and
goals (where parts should end, and a score). No state but the goals'.

**The grasp rule.** Parallel gripper. The *jaws* are the finger links' collision shapes:
their centre is the midpoint of the first two fingers' shapes (the middle of each shape's
bounding box) at the opening shown now, and the *closing axis* runs from one to the other (at the
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

**Goals** (after the grasp rule). A goal names a part (``p1``) or a type (``type=gear``:
any part of that type, each part counting for one goal at most) and a pose in the world
frame, with a tolerance in position [m] and in angle [rad]. ``score`` pairs each goal
with its part (a type goal: the nearest part of its type not taken by an earlier goal, in
the order the goals were set) and says whether it is met and by how much it is off; a
goal with no part is missing. A part that is held, or still falling, does not meet its goal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from ..collision.geometry import contains, extent, signed_distance
from ..errors import C2rvizError
from ..robot.gripper import FINGER_WORD, Gripper
from ..robot.model import Robot
from .parts import Part, PartError, Parts

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


DEFAULT_TOL_M = 0.005
"""A goal's position tolerance when none is given [m]."""
DEFAULT_TOL_RAD = math.radians(5.0)
"""A goal's angle tolerance when none is given [rad]."""
MAX_GOALS = 100
"""Goals at once."""
TYPE_PREFIX = "type="


class TooManyGoals(C2rvizError):
    def __init__(self, limit: int) -> None:
        super().__init__(f"there are already {limit} goals, the limit; remove one first")


@dataclass(frozen=True)
class Goal:
    """Where a part (``name``) or a part of a type (``type=T``) should end.

    Attributes:
        key: A part's name, or ``type=T``.
        pose: The pose in the world frame.
        tol_m: How far off its position may be [m].
        tol_rad: How far off its orientation may be [rad].
    """

    key: str
    pose: pin.SE3
    tol_m: float = DEFAULT_TOL_M
    tol_rad: float = DEFAULT_TOL_RAD

    @property
    def kind(self) -> str | None:
        """The type it asks for, or None for a named part."""
        return self.key[len(TYPE_PREFIX) :] if self.key.startswith(TYPE_PREFIX) else None


@dataclass(frozen=True)
class GoalResult:
    """One goal scored: its part (None: missing), how far off [m, rad], and whether met."""

    goal: Goal
    part: str | None
    off_m: float = math.inf
    off_rad: float = math.inf
    met: bool = False


def off(pose: pin.SE3, goal: pin.SE3) -> tuple[float, float]:
    """How far ``pose`` is from ``goal``: distance [m] and angle [rad]."""
    distance = float(np.linalg.norm(pose.translation - goal.translation))
    angle = float(np.linalg.norm(pin.log3(goal.rotation.T @ pose.rotation)))
    return distance, angle


def score(goals: Sequence[Goal], parts: Sequence[Part]) -> list[GoalResult]:
    """Each goal with its part and how far off it is (see the module)."""
    by_name = {part.name: part for part in parts}
    named = {goal.key for goal in goals if goal.kind is None}
    used: set[str] = set()
    results = []
    for goal in goals:
        kind = goal.kind
        if kind is None:
            part = by_name.get(goal.key)
        else:
            candidates = [
                p for p in parts if p.kind == kind and p.name not in used and p.name not in named
            ]
            part = min(candidates, key=lambda p: off(p.pose, goal.pose)[0], default=None)
        if part is None:
            results.append(GoalResult(goal, None))
            continue
        used.add(part.name)
        distance, angle = off(part.pose, goal.pose)
        met = (
            distance <= goal.tol_m
            and angle <= goal.tol_rad
            and part.holder is None
            and not part.falling
        )
        results.append(GoalResult(goal, part.name, distance, angle, met))
    return results


class GoalBook:
    """The goals of a world, by key, in the order they were first set."""

    def __init__(self, max_goals: int = MAX_GOALS) -> None:
        self.max_goals = max_goals
        self._goals: dict[str, Goal] = {}

    def set(self, goal: Goal, parts: Parts) -> None:
        """Add or replace ``goal``; one for a named part that is not in ``parts`` is refused
        (``UnknownPart``; a type goal with no part of its type counts as missing)."""
        if goal.kind is None:
            parts.get(goal.key)
        if goal.key not in self._goals and len(self._goals) >= self.max_goals:
            raise TooManyGoals(self.max_goals)
        self._goals[goal.key] = goal

    def remove(self, key: str) -> None:
        """Remove one goal (``all``: every one)."""
        if key == "all":
            self._goals.clear()
        elif self._goals.pop(key, None) is None:
            have = ", ".join(self._goals) or "none"
            raise PartError(f"no goal for {key!r} (goals: {have})")

    def all(self) -> list[Goal]:
        return list(self._goals.values())
