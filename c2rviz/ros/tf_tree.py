"""Our robot as ROS TF, the way robot_state_publisher publishes it.

Pinocchio merges fixed joints into frames, so the joint tree (which joint links
which parent link to which child link) is read from the URDF text itself, and
every transform is computed with Pinocchio's forward kinematics of the robot's
model. Following robot_state_publisher (ROS 2):

- a ``fixed`` joint is a constant parent -> child transform for ``/tf_static``
  (as is a ``planar`` one, which its KDL parser turns into a fixed joint);
- every ``revolute``, ``continuous`` and ``prismatic`` joint, on the chain or
  off it, mimic joints included, moves: it is named in ``/joint_states`` and its
  parent -> child transform goes on ``/tf`` with each state;
- a ``floating`` joint is skipped (no transform, not named);
- frames take the robot's prefix (``left/base_link``).

Values are SI: positions [rad or m], translations [m], rotations as unit
quaternions (x, y, z, w).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..robot import Robot
from .errors import DescriptionError

MOVING_KINDS = ("revolute", "continuous", "prismatic")
"""Joint types that move, are named in JointState and published on ``/tf``."""
_STATIC_KINDS = ("fixed", "planar")
_KINDS = (*MOVING_KINDS, *_STATIC_KINDS, "floating")
_DOCTYPE = re.compile(r"<!DOCTYPE", re.IGNORECASE)

Transform = tuple[str, str, tuple[float, float, float], tuple[float, float, float, float]]
"""(parent frame, child frame, translation x, y, z [m], rotation x, y, z, w)."""


@dataclass(frozen=True, slots=True)
class UrdfJoint:
    """One ``<joint>`` of a URDF.

    Attributes:
        name: Its name.
        kind: Its ``type``: revolute, continuous, prismatic, fixed, planar or floating.
        parent: Parent link.
        child: Child link.
        mimic: The joint it follows, or None.
        multiplier: Its value is ``multiplier * leader + offset`` (mimic only).
        offset: [rad or m] (mimic only).
    """

    name: str
    kind: str
    parent: str
    child: str
    mimic: str | None = None
    multiplier: float = 1.0
    offset: float = 0.0


def urdf_joints(xml: str) -> tuple[UrdfJoint, ...]:
    """The joints of a URDF text, in document order.

    Raises:
        DescriptionError: a DOCTYPE (refused: entities are never expanded), text
            that is not XML, or a joint without its type, parent or child.
    """
    if _DOCTYPE.search(xml):
        raise DescriptionError("the URDF has a DOCTYPE, which is refused (entities are not read)")
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise DescriptionError(f"the URDF is not XML: {exc}") from None
    joints = []
    for element in root.findall("joint"):
        name = element.get("name", "")
        kind = element.get("type", "")
        parent = element.find("parent")
        child = element.find("child")
        if kind not in _KINDS or parent is None or child is None:
            raise DescriptionError(
                f"URDF joint {name!r} needs a type ({', '.join(_KINDS)}), a parent and a child"
            )
        mimic = element.find("mimic")
        try:
            multiplier = float(mimic.get("multiplier", 1.0)) if mimic is not None else 1.0
            offset = float(mimic.get("offset", 0.0)) if mimic is not None else 0.0
        except ValueError:
            raise DescriptionError(f"URDF joint {name!r}: a mimic number is not a number") from None
        joints.append(
            UrdfJoint(
                name,
                kind,
                parent.get("link", ""),
                child.get("link", ""),
                mimic.get("joint") if mimic is not None else None,
                multiplier,
                offset,
            )
        )
    return tuple(joints)


class TfTree:
    """The TF of one robot: its moving joints' states and transforms, and its fixed ones."""

    def __init__(self, robot: Robot, prefix: str = "") -> None:
        """Read the joint tree of ``robot.source.xml`` and match it to ``robot.model``.

        Args:
            robot: The robot (its model built from the same URDF, mimic joints following).
            prefix: Put before every frame name (``left/``), or ``""``.

        Raises:
            DescriptionError: the URDF cannot be read, or names a link or joint the
                model does not have.
        """
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        self.prefix = prefix
        joints = urdf_joints(robot.source.xml)
        self.moving = tuple(j for j in joints if j.kind in MOVING_KINDS)
        self.fixed = tuple(j for j in joints if j.kind in _STATIC_KINDS)
        children = {j.child for j in joints}
        roots = [j.parent for j in joints if j.parent not in children]
        self.root = prefix + (roots[0] if roots else robot.base)
        """The frame of the URDF's root link (where a cell places the robot)."""
        self.names = tuple(j.name for j in self.moving)
        """The JointState names, in URDF order."""
        index = {name: k for k, name in enumerate(self.names)}
        self._direct: list[tuple[int, int]] = []  # (position index, idx_q)
        self._continuous: list[tuple[int, int]] = []  # (position index, idx_q of cos)
        self._mimic: list[tuple[int, int, float, float]] = []  # (index, leader's, mult, offset)
        # (parent frame, child frame, joint id, the parent link in its joint's frame and the
        # child link in the moving joint's frame, each None where it is the identity)
        self._moving_frames: list[tuple[str, str, int, pin.SE3 | None, pin.SE3 | None]] = []
        for k, joint in enumerate(self.moving):
            jid = self._joint_id(joint.name)
            if joint.mimic is not None:
                if joint.mimic not in index:
                    raise DescriptionError(
                        f"joint {joint.name!r} mimics {joint.mimic!r}, which is not a moving joint"
                    )
                self._mimic.append((k, index[joint.mimic], joint.multiplier, joint.offset))
            elif self.model.joints[jid].nq == 2:
                self._continuous.append((k, self.model.joints[jid].idx_q))
            else:
                self._direct.append((k, self.model.joints[jid].idx_q))
            parent, child = self._frame(joint.parent), self._frame(joint.child)
            frames = self.model.frames
            if (frames[parent].parentJoint, frames[child].parentJoint) != (
                self.model.parents[jid],
                jid,
            ):
                raise DescriptionError(
                    f"joint {joint.name!r} does not link {joint.parent!r} to {joint.child!r} "
                    f"in the model {self.model.name}"
                )
            before, after = frames[parent].placement.inverse(), frames[child].placement.copy()
            self._moving_frames.append(
                (
                    prefix + joint.parent,
                    prefix + joint.child,
                    jid,
                    None if before.isIdentity() else before,
                    None if after.isIdentity() else after,
                )
            )
        self._mimic = _leaders_first(self._mimic, self.names)
        self._chain_k = [index[name] for name in robot.joint_names]
        self._direct_k = np.array([k for k, _ in self._direct], dtype=int)
        self._direct_q = np.array([q for _, q in self._direct], dtype=int)
        self._static = self._static_transforms()

    def _joint_id(self, name: str) -> int:
        if not self.model.existJointName(name):
            raise DescriptionError(f"URDF joint {name!r} is not in the model {self.model.name}")
        return int(self.model.getJointId(name))

    def _frame(self, link: str) -> int:
        if not self.model.existFrame(link, pin.BODY):
            raise DescriptionError(f"URDF link {link!r} is not in the model {self.model.name}")
        return int(self.model.getFrameId(link, pin.BODY))

    def _static_transforms(self) -> tuple[Transform, ...]:
        pin.framesForwardKinematics(self.model, self.data, self.robot.neutral)
        out = []
        frames = self.model.frames
        for joint in self.fixed:
            parent, child = frames[self._frame(joint.parent)], frames[self._frame(joint.child)]
            if parent.parentJoint == child.parentJoint:  # exact: no trip through the world
                placement = parent.placement.actInv(child.placement)
            else:  # a planar joint (Pinocchio moves it; ROS holds it fixed)
                placement = self.data.oMf[self._frame(joint.parent)].actInv(
                    self.data.oMf[self._frame(joint.child)]
                )
            out.append(_transform(self.prefix + joint.parent, self.prefix + joint.child, placement))
        return tuple(out)

    def static_transforms(self) -> list[Transform]:
        """Every fixed joint's parent -> child transform (constant), for ``/tf_static``."""
        return list(self._static)

    def joint_positions(self, full_q: np.ndarray) -> tuple[tuple[str, ...], list[float]]:
        """JointState names and positions [rad or m] for Pinocchio configuration ``full_q``.

        A continuous joint (stored as cos, sin) gives its angle in (-pi, pi]; a mimic
        joint ``multiplier * leader + offset``, as robot_state_publisher computes it.
        """
        positions = np.empty(len(self.names))
        positions[self._direct_k] = full_q[self._direct_q]
        for k, idx in self._continuous:
            positions[k] = math.atan2(full_q[idx + 1], full_q[idx])
        for k, leader, multiplier, offset in self._mimic:
            positions[k] = multiplier * positions[leader] + offset
        return self.names, positions.tolist()

    def joint_velocities(self, chain_v: Sequence[float]) -> list[float]:
        """JointState velocities [rad/s or m/s] from the chain's: 0 off the chain, mimics follow."""
        velocities = [0.0] * len(self.names)
        for k, value in zip(self._chain_k, chain_v):
            velocities[k] = float(value)
        for k, leader, multiplier, _ in self._mimic:
            velocities[k] = multiplier * velocities[leader]
        return velocities

    def moving_transforms(self, full_q: np.ndarray) -> list[Transform]:
        """Each moving joint's parent -> child transform at ``full_q``, for ``/tf``."""
        pin.forwardKinematics(self.model, self.data, full_q)
        limi = self.data.liMi
        out: list[Transform] = []
        for parent, child, jid, before, after in self._moving_frames:
            placement = limi[jid]  # the joint's frame in its parent joint's frame
            if before is not None:
                placement = before * placement
            if after is not None:
                placement = placement * after
            x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(placement).tolist()
            out.append((parent, child, (x, y, z), (qx, qy, qz, qw)))
        return out


def _leaders_first(
    mimics: list[tuple[int, int, float, float]], names: Sequence[str]
) -> list[tuple[int, int, float, float]]:
    """Mimic joints ordered so that a mimic's leader comes before it."""
    waiting = {m[0]: m for m in mimics}
    ordered: list[tuple[int, int, float, float]] = []
    while waiting:
        ready = [m for m in waiting.values() if m[1] not in waiting]
        if not ready:
            raise DescriptionError(
                "mimic joints follow each other in a loop: "
                + ", ".join(names[k] for k in sorted(waiting))
            )
        for m in ready:
            ordered.append(m)
            del waiting[m[0]]
    return ordered


def _transform(parent: str, child: str, placement: pin.SE3) -> Transform:
    x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(placement).tolist()
    return (parent, child, (x, y, z), (qx, qy, qz, qw))
