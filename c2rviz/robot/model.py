"""The robot: a Pinocchio model and the serial chain the commands drive.

Pinocchio is the one source of kinematic truth: joint names, their order,
limits and every link pose come from the model built here. Chain joint ``i``
(the index clients send) is the i-th movable joint on the path from the base
link to the end-effector link; fixed joints are frames in Pinocchio and so are
skipped by construction. Every value is SI: radians for revolute joints,
metres for prismatic ones.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import RobotError
from .gripper import Gripper, find_fingers
from .sources import RobotSource, load_source

_UNBOUNDED = 1e10  # Pinocchio's stand-in for "no limit" is a huge number.

CONTINUOUS_LIMIT = 1e6
"""Limit [rad, or m] of a joint the URDF leaves unbounded: it takes -1e6..1e6.

About 159,000 turns (57,295,779.51 deg), so no real use meets it; finite, so
every value ``where`` replies is a finite number that can be sent back (an
unbounded joint once took 1.7e308 rad, and ``where`` in degrees said ``inf``).
A value past it is refused like any limit; motion planning keeps within it too
(it reads ``Robot.lower``/``upper``)."""


@dataclass(frozen=True, slots=True)
class ChainJoint:
    """One movable joint of the chain.

    Attributes:
        name: Joint name from the URDF.
        prismatic: True for a prismatic joint (values in [m]), else revolute [rad].
        lower: Lower limit [rad or m]; ``-CONTINUOUS_LIMIT`` for a continuous joint.
        upper: Upper limit [rad or m]; ``CONTINUOUS_LIMIT`` for a continuous joint.
        idx_q: Index of the joint's first entry in Pinocchio's configuration.
        nq: 1, or 2 for a continuous joint (stored as cos, sin).
        continuous: The URDF gives no limits (a continuous joint): any angle, not
            wrapped (720 deg stays 720), within the finite ``CONTINUOUS_LIMIT``.
    """

    name: str
    prismatic: bool
    lower: float
    upper: float
    idx_q: int
    nq: int
    continuous: bool = False


class Robot:
    """A Pinocchio model with a chosen serial chain from ``base`` to ``eelink``."""

    def __init__(
        self,
        model: pin.Model,
        base: str | None = None,
        eelink: str | None = None,
        source: RobotSource | None = None,
    ) -> None:
        """Choose the chain of ``model``.

        Args:
            model: A Pinocchio model built from a URDF.
            base: Link the chain starts at; with ``eelink`` None, both default
                to the root and the only leaf of an unbranched tree.
            eelink: Link the chain ends at (the end effector).
            source: The description the model was built from (its meshes are
                looked up through it).

        Raises:
            RobotError: unknown links, a branching tree with no ends given, or
                an eelink that is not below base.
        """
        self.model = model
        self.data = model.createData()
        self.name = model.name
        self.source = source if source is not None else RobotSource("")
        links = self.link_names()
        if base is None or eelink is None:
            root, leaves = self._root_and_leaves()
            if eelink is None and len(leaves) != 1:
                raise RobotError(
                    f"{self.name} branches, so name the end-effector link "
                    f"(--eelink or the ini's eelink); candidate end links: {', '.join(leaves)}"
                )
            base = base if base is not None else root
            eelink = eelink if eelink is not None else leaves[0]
        for role, link in (("base", base), ("eelink", eelink)):
            if link not in links:
                raise RobotError(
                    f"{role} link {link!r} is not in {self.name}; its links are: "
                    + ", ".join(links)
                )
        self.base = base
        self.eelink = eelink
        self.base_frame = model.getFrameId(base, pin.BODY)
        self.ee_frame = model.getFrameId(eelink, pin.BODY)
        self.joints = self._chain()
        self.joint_names = tuple(joint.name for joint in self.joints)
        self.lower = tuple(joint.lower for joint in self.joints)
        self.upper = tuple(joint.upper for joint in self.joints)
        self.prismatic = tuple(joint.prismatic for joint in self.joints)
        self.neutral = self._neutral()
        self.home = tuple(
            0.0 if joint.nq == 2 else float(self.neutral[joint.idx_q]) for joint in self.joints
        )
        """Chain values of ``home``: 0, or the nearest limit where 0 is outside [rad or m]."""
        self._simple_q = all(joint.nq == 1 for joint in self.joints)
        self._idx_q = np.array([joint.idx_q for joint in self.joints], dtype=int)
        self.gripper: Gripper | None = find_fingers(model, self._chain_ids, self.neutral)
        """Its gripper: finger joints below the chain (``gripper.find_fingers``), or the
        ini's (``gripper.make_gripper``); None: it has none."""
        pin.framesForwardKinematics(model, self.data, self.neutral)
        self.base_placement = self.data.oMf[self.base_frame].copy()

    @classmethod
    def from_urdf(
        cls,
        path: str | Path,
        base: str | None = None,
        eelink: str | None = None,
        *,
        package_paths: Sequence[str | Path] = (),
        xacro_args: Mapping[str, str] | Iterable[str] = (),
    ) -> Robot:
        """Build the model from a URDF or xacro file (see ``sources.load_source``)."""
        return cls.from_source(load_source(path, package_paths, xacro_args), base, eelink)

    @classmethod
    def from_source(
        cls, source: RobotSource, base: str | None = None, eelink: str | None = None
    ) -> Robot:
        """Build the model from a loaded description (mimic joints follow their leader)."""
        try:
            model = pin.buildModelFromXML(source.xml, mimic=True)
        except (RuntimeError, ValueError) as exc:
            where = f" {source.path}" if source.path else ""
            raise RobotError(f"cannot read the URDF{where}: {exc}") from exc
        return cls(model, base, eelink, source)

    @property
    def n(self) -> int:
        """Number of chain joints."""
        return len(self.joints)

    def link_names(self) -> list[str]:
        """Every link (Pinocchio body frame) of the model, in model order."""
        return [f.name for f in self.model.frames if f.type == pin.FrameType.BODY]

    def _root_and_leaves(self) -> tuple[str, list[str]]:
        """The root link and the links with no child links."""
        frames = self.model.frames
        bodies = [i for i, f in enumerate(frames) if f.type == pin.FrameType.BODY]
        # A body hangs from a joint frame, which hangs from the parent body.
        parent = {i: frames[frames[i].parentFrame].parentFrame for i in bodies}
        has_child = set(parent.values())
        roots = [frames[i].name for i in bodies if parent[i] not in parent]
        leaves = [frames[i].name for i in bodies if i not in has_child]
        return roots[0], leaves

    def _chain(self) -> tuple[ChainJoint, ...]:
        model = self.model
        base_joint = model.frames[self.base_frame].parentJoint
        joint = model.frames[self.ee_frame].parentJoint
        path: list[int] = []
        while joint != base_joint:
            if joint == 0:
                raise RobotError(
                    f"eelink {self.eelink!r} is not below base {self.base!r} in {self.name}"
                )
            path.append(joint)
            joint = model.parents[joint]
        self._chain_ids = list(reversed(path))
        chain = []
        for j in reversed(path):
            jm = model.joints[j]
            if jm.nq == 0:  # a mimic joint follows its leader; it is not an index
                continue
            kind = jm.shortname()
            if jm.nv != 1:
                raise RobotError(
                    f"joint {model.names[j]!r} ({kind}) has {jm.nv} degrees of freedom; "
                    "only revolute, continuous and prismatic joints can be in the chain"
                )
            prismatic = kind.startswith("JointModelP")
            lower = float(model.lowerPositionLimit[jm.idx_q])
            upper = float(model.upperPositionLimit[jm.idx_q])
            # nq 2: a continuous joint, stored as (cos, sin), whose limits mean nothing
            continuous = jm.nq == 2 or (lower <= -_UNBOUNDED and upper >= _UNBOUNDED)
            if continuous:
                lower, upper = -CONTINUOUS_LIMIT, CONTINUOUS_LIMIT
            chain.append(
                ChainJoint(model.names[j], prismatic, lower, upper, jm.idx_q, jm.nq, continuous)
            )
        if not chain:
            raise RobotError(
                f"no movable joint between base {self.base!r} and eelink {self.eelink!r} "
                f"in {self.name}"
            )
        return tuple(chain)

    def _neutral(self) -> np.ndarray:
        """Pinocchio's neutral configuration, kept within each joint's limits.

        A 1-DoF joint whose limits exclude 0 sits at its nearest limit; this is
        ``home`` for chain joints, and where off-chain joints stay.
        """
        model = self.model
        q = pin.neutral(model)
        for jm in model.joints[1:]:
            if jm.nq == 1 and jm.nv == 1:
                lower = model.lowerPositionLimit[jm.idx_q]
                upper = model.upperPositionLimit[jm.idx_q]
                if lower <= upper:
                    q[jm.idx_q] = min(max(q[jm.idx_q], lower), upper)
        return q

    def configuration(self, q: Sequence[float], opening: float | None = None) -> np.ndarray:
        """Pinocchio's full configuration for chain values ``q`` [rad or m].

        Joints off the chain stay at their neutral value (0, or the nearest limit
        when 0 is outside them), but for the gripper's fingers at ``opening`` (0
        closed .. 1 open) when one is given; mimic joints follow their leader.
        """
        full = self.neutral.copy()
        if opening is not None and self.gripper is not None:
            self.gripper.apply(full, opening)
        if self._simple_q:
            full[self._idx_q] = q
        else:
            for joint, value in zip(self.joints, q):
                if joint.nq == 2:
                    full[joint.idx_q] = math.cos(value)
                    full[joint.idx_q + 1] = math.sin(value)
                else:
                    full[joint.idx_q] = value
        return full

    def ee_pose(self, q: Sequence[float]) -> pin.SE3:
        """End-effector placement in the base frame for chain values ``q``."""
        pin.forwardKinematics(self.model, self.data, self.configuration(q))
        ee = pin.updateFramePlacement(self.model, self.data, self.ee_frame)
        return self.base_placement.actInv(ee)

    def random(self, rng: np.random.Generator) -> list[float]:
        """Chain values drawn uniformly within the limits ([-pi, pi] if continuous)."""
        return [
            float(rng.uniform(-math.pi, math.pi))
            if joint.continuous
            else float(rng.uniform(joint.lower, joint.upper))
            for joint in self.joints
        ]
