"""A robot's gripper: finger joints off the chain, one opening from 0 (closed) to 1 (open).

A gripper is found in the URDF (``find_fingers``: the 1-DoF joints below the chain's
last joint, off the chain, whose name says ``finger``; each closes at its lower limit
and opens at its upper one) or named by the ini (``make_gripper``, with each joint's
closed and open values). Mimic joints follow their leader in Pinocchio's model, so
only leaders are set. ``opening`` 0..1 maps linearly to each leader's value; the
jaws' ``separation`` [m] is the distance between the first two finger links (or the
one finger's travel) beyond where they are when closed.

Pure: no state here. The world holds each robot's opening and moves it on its clock.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..errors import RobotError

FINGER_WORD = "finger"
"""A joint off the chain whose name holds this (any case) is a finger of the URDF's gripper."""

_DEFAULT_STROKE_S = 1.0  # closed to open when the URDF gives no finger velocity [s]
_TABLE_POINTS = 33  # openings at which the separation is computed, then interpolated


@dataclass(frozen=True)
class Gripper:
    """The finger joints a gripper moves, and what its opening means.

    Attributes:
        name: Its name in CRCL statuses (the link the fingers hang from).
        joints: The leader finger joints (mimic joints follow them).
        idx_q: Each leader's index in Pinocchio's full configuration.
        closed: Each leader's value when closed [rad or m].
        opened: Each leader's value when open [rad or m].
        stroke_s: Time from closed to open (or back) at full speed [s].
        separations: The jaws' separation [m] at ``_TABLE_POINTS`` even openings 0..1.
    """

    name: str
    joints: tuple[str, ...]
    idx_q: tuple[int, ...]
    closed: tuple[float, ...]
    opened: tuple[float, ...]
    stroke_s: float
    separations: tuple[float, ...] = ()

    def values(self, opening: float) -> tuple[float, ...]:
        """Each leader's value [rad or m] at ``opening`` (0 closed .. 1 open)."""
        return tuple(c + opening * (o - c) for c, o in zip(self.closed, self.opened))

    def apply(self, configuration: np.ndarray, opening: float) -> None:
        """Set the leaders of Pinocchio's full ``configuration`` for ``opening``, in place."""
        for index, value in zip(self.idx_q, self.values(opening)):
            configuration[index] = value

    def separation(self, opening: float) -> float:
        """The jaws' separation [m] at ``opening`` (0 when closed)."""
        table = self.separations
        if not table:
            return 0.0
        x = min(max(opening, 0.0), 1.0) * (len(table) - 1)
        k = min(int(x), len(table) - 2)
        return table[k] + (x - k) * (table[k + 1] - table[k])

    def opening_of(self, values: Sequence[float]) -> float:
        """The opening (clamped to 0..1) that the first leader's ``values[0]`` means (a
        vacuum gripper, with no joints: 1, suction off)."""
        if not self.closed:
            return 1.0
        span = self.opened[0] - self.closed[0]
        return min(max((values[0] - self.closed[0]) / span, 0.0), 1.0) if span else 0.0


def find_fingers(
    model: pin.Model, chain_joints: Sequence[int], neutral: np.ndarray
) -> Gripper | None:
    """The URDF's gripper: finger joints hanging below the chain's last joint, if any.

    Args:
        model: The robot's Pinocchio model (mimic joints built as such).
        chain_joints: The chain's joint ids, base to end.
        neutral: The model's neutral configuration (fingers off the chain stay there).
    """
    last = chain_joints[-1]
    leaders: list[tuple[str, float, float]] = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if j in chain_joints or FINGER_WORD not in model.names[j].lower():
            continue
        if joint.nq != 1 or joint.nv != 1 or not _below(model, j, last):
            continue
        lower = float(model.lowerPositionLimit[joint.idx_q])
        upper = float(model.upperPositionLimit[joint.idx_q])
        if not (np.isfinite(lower) and np.isfinite(upper)) or abs(upper) > 1e9 or lower >= upper:
            continue  # a finger with no limits has no closed and open
        leaders.append((model.names[j], lower, upper))
    if not leaders:
        return None
    return make_gripper(model, leaders, neutral)


def make_gripper(
    model: pin.Model, joints: Sequence[tuple[str, float, float]], neutral: np.ndarray
) -> Gripper:
    """A gripper moving ``joints``: (name, closed value, open value [rad or m]) each.

    Raises:
        RobotError: a joint that is not in the model, or not a 1-DoF joint that can be
            set (a mimic joint follows its leader: name the leader).
    """
    names = list(model.names)
    idx_q, stroke = [], 0.0
    for name, closed, opened in joints:
        if name not in names:
            raise RobotError(f"gripper joint {name!r} is not in {model.name}")
        joint = model.joints[names.index(name)]
        if joint.nq != 1 or joint.nv != 1:
            raise RobotError(
                f"gripper joint {name!r} of {model.name} is not a 1-DoF joint that can be set "
                "(a mimic joint follows its leader: name the leader)"
            )
        if closed == opened:
            raise RobotError(f"gripper joint {name!r}: its closed and open values are the same")
        idx_q.append(joint.idx_q)
        velocity = float(model.velocityLimit[joint.idx_v])
        if 0.0 < velocity < 1e9:
            stroke = max(stroke, abs(opened - closed) / velocity)
    first = names.index(joints[0][0])
    gripper = Gripper(
        name=_parent_link(model, joints[0][0]),
        joints=tuple(name for name, _, _ in joints),
        idx_q=tuple(idx_q),
        closed=tuple(float(closed) for _, closed, _ in joints),
        opened=tuple(float(opened) for _, _, opened in joints),
        stroke_s=stroke or _DEFAULT_STROKE_S,
    )
    moved = _finger_bodies(model, first, [names.index(name) for name, _, _ in joints])
    return replace(gripper, separations=_separations(model, gripper, moved, neutral))


def _below(model: pin.Model, joint: int, ancestor: int) -> bool:
    while joint != 0:
        joint = model.parents[joint]
        if joint == ancestor:
            return True
    return False


def _parent_link(model: pin.Model, joint_name: str) -> str:
    """The link a joint hangs from (a CRCL GripperName is an NMTOKEN: a link name is one)."""
    frame = model.frames[model.getFrameId(joint_name, pin.JOINT)]
    parent = model.frames[frame.parentFrame].name
    return parent if parent and parent != "universe" else joint_name


def _finger_bodies(model: pin.Model, first: int, leaders: Sequence[int]) -> list[int]:
    """The body frames the fingers move: children of the leaders and of finger-named joints
    (mimic ones) next to them, in model order."""
    movers = set(leaders)
    parent = model.parents[first]
    for j in range(1, model.njoints):
        if model.parents[j] == parent and FINGER_WORD in model.names[j].lower():
            movers.add(j)
    bodies = [
        i
        for i, frame in enumerate(model.frames)
        if frame.type == pin.FrameType.BODY and frame.parentJoint in movers
    ]
    seen: set[int] = set()
    firsts = []
    for i in bodies:  # one body per joint: its first
        joint = model.frames[i].parentJoint
        if joint not in seen:
            seen.add(joint)
            firsts.append(i)
    return firsts


def _separations(
    model: pin.Model, gripper: Gripper, bodies: Sequence[int], neutral: np.ndarray
) -> tuple[float, ...]:
    """The separation at ``_TABLE_POINTS`` even openings: two fingers' distance, or one
    finger's travel, beyond what it is when closed [m]."""
    if not bodies:
        return ()
    data = model.createData()

    def places(opening: float) -> list[np.ndarray]:
        q = neutral.copy()
        gripper.apply(q, opening)
        pin.framesForwardKinematics(model, data, q)
        return [data.oMf[body].translation.copy() for body in bodies[:2]]

    start = places(0.0)
    closed = float(np.linalg.norm(start[0] - start[1])) if len(start) == 2 else 0.0
    table = []
    for k in range(_TABLE_POINTS):
        now = places(k / (_TABLE_POINTS - 1))
        far = now[1] if len(now) == 2 else start[0]  # two fingers apart, or one's travel
        spread = np.linalg.norm(now[0] - far)
        table.append(max(float(spread) - closed, 0.0))
    return tuple(table)
