"""The chain as the IK solves it, a Pinocchio model of the chain alone with a tool, and
the targets it is asked to reach.

Joints off the chain are locked at their neutral values (as
``Robot.configuration`` leaves them), so the model's configuration is exactly
the chain's, except that a continuous joint is stored as (cos, sin). A frame
for the tool point hangs from the end-effector link; its offset can change
between calls. Conversions between chain values and the model's
configuration live here, and nowhere else.

``ReachBound``: how far the tool point can ever be from the arm's first joint, a bound
computed once. Walk the chain from the tool frame up to the first joint. A revolute joint
turns about its own origin, so the distance from one joint's origin to the
next is fixed (the length of the next joint's placement); a prismatic joint
adds at most its longest travel. By the triangle inequality the tool point
stays within the sum of those lengths (and the tool offset) of the first
joint's origin, which is fixed in the model's world frame. A target farther
than that is refused before any solve.

What the IK is asked for (``Target``): a full tool pose, or a tool point with its
orientation free. A full pose is a ``pin.SE3`` (as before); ``PointTarget`` asks only for the
tool point's position, leaving its orientation to the solver (it stays near
the seed's). Both are in the robot's base frame, as ``Robot.ee_pose`` gives.

``Unreachable`` is the IK's refusal of a target: how close the tool could get, beside
the tolerance it missed.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, JointCountError
from ..robot.model import Robot

TOOL_FRAME = "c2rviz_ik_tool"


def chain_model(robot: Robot) -> pin.Model:
    """The chain alone: every joint off the chain locked at its neutral value.

    A reduced model rather than pink on the full model with off-chain joints
    held: pink has no way to freeze joints short of faking their limits, and
    the reduced configuration is then the chain's. A mimic joint on the chain
    stays (and follows its leader) when its leader is a chain joint; else it is
    locked with everything else, as ``Robot.configuration`` keeps its leader
    neutral.
    """
    model = robot.model
    chain = set(robot.joint_names)
    keep = {j for j in range(1, model.njoints) if model.names[j] in chain}
    for mimic, leader in zip(model.mimicking_joints, model.mimicked_joints):
        if leader in keep:
            keep.add(mimic)
    locked = [j for j in range(1, model.njoints) if j not in keep]
    model = model.copy()
    if not locked:
        return model
    # Pinocchio finds a locked joint's frame by name alone and refuses when a
    # link has the same name (so100's "gripper"): rename such joints first.
    frame_names = Counter(frame.name for frame in model.frames)
    for j in locked:
        name = model.names[j]
        if frame_names[name] > 1:
            model.frames[model.getFrameId(name, pin.JOINT)].name = f"{name} (joint)"
            model.names[j] = f"{name} (joint)"
    return pin.buildReducedModel(model, locked, robot.neutral)


class IkChain:
    """The chain's model with a tool frame, and conversions to and from chain values.

    Attributes:
        robot: The robot whose chain this is.
        model: The chain's model, with the tool frame ``TOOL_FRAME``.
        tool_frame: Index of the tool frame in the model.
        base_placement: Base link placement in the model's world frame.
        lower: The model's lower position limits (cos/sin bounds for continuous joints).
        upper: The model's upper position limits.
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        model = chain_model(robot)
        ee = model.getFrameId(robot.eelink, pin.BODY)
        self._ee_placement = model.frames[ee].placement.copy()
        self.tool_frame = model.addFrame(
            pin.Frame(
                TOOL_FRAME,
                model.frames[ee].parentJoint,
                ee,
                self._ee_placement,
                pin.FrameType.OP_FRAME,
            )
        )
        self.model = model
        self.data = model.createData()
        pin.framesForwardKinematics(model, self.data, pin.neutral(model))
        self.base_placement = self.data.oMf[model.getFrameId(robot.base, pin.BODY)].copy()
        self.lower = model.lowerPositionLimit.copy()
        self.upper = model.upperPositionLimit.copy()
        self._idx_q = [model.joints[model.getJointId(j.name)].idx_q for j in robot.joints]
        self._continuous = [j.continuous and j.nq == 2 for j in robot.joints]
        self._wraps = [not (j.prismatic or j.continuous) for j in robot.joints]
        self._turns = [
            wraps and j.upper - j.lower > math.tau for wraps, j in zip(self._wraps, robot.joints)
        ]
        self._plain = not any(self._continuous)  # every chain value is one model entry
        self._idx = np.array(self._idx_q, dtype=int)
        self._turn_idx = np.flatnonzero(self._turns)

    def set_tool(self, tool: pin.SE3 | None) -> None:
        """Put the tool frame at ``tool`` from the end-effector link (identity when None)."""
        placement = self._ee_placement * (tool if tool is not None else pin.SE3.Identity())
        self.model.frames[self.tool_frame].placement = placement

    def tool_pose(self, q: Sequence[float]) -> pin.SE3:
        """Tool placement in the base frame for chain values ``q`` [rad or m]."""
        pin.framesForwardKinematics(self.model, self.data, self.to_model(q))
        return self.base_placement.actInv(self.data.oMf[self.tool_frame])

    def to_model(self, q: Sequence[float]) -> np.ndarray:
        """The model's configuration for chain values ``q``, within the limits.

        A revolute joint outside its limits is first turned by whole turns
        towards them (the same pose), then clipped.

        Raises:
            JointCountError: ``q`` does not have one value per chain joint.
        """
        joints = self.robot.joints
        if len(q) != len(joints):
            raise JointCountError(len(joints), len(q))
        out = pin.neutral(self.model)
        for i, (idx, value) in enumerate(zip(self._idx_q, q)):
            if self._continuous[i]:
                out[idx], out[idx + 1] = math.cos(value), math.sin(value)
                continue
            lower, upper = joints[i].lower, joints[i].upper
            if self._wraps[i] and not lower <= value <= upper:
                turns = math.ceil((lower - value) / math.tau) if value < lower else 0
                turns -= math.ceil((value - upper) / math.tau) if value > upper else 0
                value += turns * math.tau
            out[idx] = min(max(value, lower), upper)
        return out

    def to_chain(self, q: np.ndarray, near: Sequence[float]) -> tuple[float, ...]:
        """Chain values [rad or m], each revolute joint on the turn nearest ``near``.

        A continuous joint takes any turn; a revolute joint whose range spans
        more than a turn (a UR arm's +-360 deg) takes the whole-turn equivalent
        nearest ``near`` that is within its limits: the same pose, less motion.
        A value within half a turn of ``near`` is returned exactly as it is.
        """
        if not self._plain:
            return self._to_chain_turning(q, near)
        values = q[self._idx]
        if len(self._turn_idx):
            turns = self._turn_idx
            gap = values[turns] - np.asarray(near, dtype=float)[turns]
            if (np.abs(gap) > math.pi).any():
                return self._to_chain_turning(q, near)
        return tuple(values.tolist())

    def _to_chain_turning(self, q: np.ndarray, near: Sequence[float]) -> tuple[float, ...]:
        """``to_chain`` one joint at a time, for continuous joints and whole turns."""
        out = []
        joints = self.robot.joints
        for i, idx in enumerate(self._idx_q):
            if self._continuous[i]:
                angle = math.atan2(q[idx + 1], q[idx])
                out.append(near[i] + math.remainder(angle - near[i], math.tau))
                continue
            value = float(q[idx])
            if self._turns[i] and abs(value - near[i]) > math.pi:
                lower, upper = joints[i].lower, joints[i].upper
                nearest = near[i] + math.remainder(value - near[i], math.tau)
                other = math.copysign(math.tau, near[i] - nearest)  # the next nearest turn
                for candidate in (nearest, nearest + other, nearest - other):
                    if lower <= candidate <= upper:
                        value = candidate
                        break
            out.append(value)
        return tuple(out)


class ReachBound:
    """A sphere no configuration takes the tool point out of.

    Attributes:
        center: The first chain joint's origin, in the model's world frame [m].
        length_m: Largest distance from ``center`` to the end-effector joint's
            origin, plus nothing for the tool [m] (inf when it cannot be bounded).
    """

    def __init__(self, chain: IkChain) -> None:
        self.chain = chain
        model = chain.model
        joint = model.frames[chain.tool_frame].parentJoint
        length = 0.0
        while model.parents[joint] != 0:
            length += _link_length(model, joint)
            joint = model.parents[joint]
        # the first joint: its placement from the (fixed) world is the centre
        self.center = model.jointPlacements[joint].translation.copy()
        self.length_m = length + _travel(model, joint)

    def radius_m(self) -> float:
        """The bound with the current tool offset (``IkChain.set_tool``) [m]."""
        tool = self.chain.model.frames[self.chain.tool_frame].placement.translation
        return self.length_m + float(np.linalg.norm(tool))

    def beyond(self, position: np.ndarray) -> float:
        """How far ``position`` (world frame) is outside the sphere [m]; <= 0 inside."""
        return float(np.linalg.norm(position - self.center)) - self.radius_m()


def _link_length(model: pin.Model, joint: int) -> float:
    """Largest distance from the parent joint's origin to this joint's origin [m]."""
    return float(np.linalg.norm(model.jointPlacements[joint].translation)) + _travel(model, joint)


def _travel(model: pin.Model, joint: int) -> float:
    """Largest distance this joint moves its own origin [m]: 0 for a revolute joint."""
    joint_model = model.joints[joint]
    kind = joint_model.shortname()
    if kind == "JointModelMimic":  # follows its leader; prismatic travel is not bounded here
        kind = joint_model.extract().shortname()
        return 0.0 if kind.startswith("JointModelR") else math.inf
    if kind.startswith("JointModelR"):
        return 0.0
    if kind.startswith("JointModelP") and joint_model.nq == 1:
        lower = float(model.lowerPositionLimit[joint_model.idx_q])
        upper = float(model.upperPositionLimit[joint_model.idx_q])
        return max(abs(lower), abs(upper))  # huge for an unbounded slide: no refusal
    return math.inf  # another kind of joint: no bound


@dataclass(frozen=True, slots=True)
class PointTarget:
    """A tool target with its orientation free: the tool point at ``position``.

    Attributes:
        position: x, y, z of the tool point in the base frame [m].
    """

    position: tuple[float, float, float]

    @classmethod
    def at(cls, xyz: Sequence[float] | np.ndarray) -> PointTarget:
        """The point ``(x, y, z)`` [m]; refuses anything but three finite numbers."""
        values = tuple(float(v) for v in xyz)
        if len(values) != 3 or not all(np.isfinite(values)):
            raise ValueError(f"a point target needs three finite numbers [m], got {values}")
        return cls((values[0], values[1], values[2]))

    def __str__(self) -> str:
        return "point " + ",".join(f"{v:g}" for v in self.position)


Target: TypeAlias = pin.SE3 | PointTarget
"""A tool pose (``pin.SE3``: position and orientation) or a ``PointTarget`` (position only)."""


@dataclass(frozen=True, slots=True)
class Goal:
    """A target in the IK model's world frame, as the descents use it.

    Attributes:
        position: Tool point [m], world frame, shape (3,).
        rotation: Tool orientation (3x3), world frame; None when free.
    """

    position: np.ndarray
    rotation: np.ndarray | None


def goal_in_world(target: Target, base_placement: pin.SE3) -> Goal:
    """``target`` (base frame) in the world frame of a model whose base is at ``base_placement``."""
    if isinstance(target, PointTarget):
        return Goal(base_placement.act(np.array(target.position, dtype=np.float64)), None)
    world = base_placement * target
    return Goal(world.translation.copy(), world.rotation.copy())


_PROMISE_M = 1e-4  # the tolerances IkSettings promises: 0.1 mm ...
_PROMISE_RAD = math.radians(0.1)  # ... and 0.1 deg


class Unreachable(C2rvizError):
    """No chain values within the limits put the tool at the target.

    Attributes:
        distance_m: Position error of the closest tool pose found [m]; when
            ``reach_m`` is set, a lower bound on every pose's position error.
        angle_rad: Orientation error of that pose [rad]; 0 when the orientation
            was free, or when ``reach_m`` is set (no pose was searched).
        position_tolerance_m: The position error an answer may have [m].
        angle_tolerance_rad: The orientation error an answer may have [rad].
        orientation_free: The target was a point (``PointTarget``).
        reach_m: Set when the target is beyond the arm's reach, refused before
            any solve: the most the tool point can be from the first joint [m].
        from_first_joint_m: With ``reach_m``, the target's distance from the first joint [m].
    """

    def __init__(
        self,
        distance_m: float,
        angle_rad: float,
        position_tolerance_m: float = _PROMISE_M,
        angle_tolerance_rad: float = _PROMISE_RAD,
        *,
        orientation_free: bool = False,
        reach_m: float | None = None,
        from_first_joint_m: float | None = None,
    ) -> None:
        self.distance_m = distance_m
        self.angle_rad = angle_rad
        self.position_tolerance_m = position_tolerance_m
        self.angle_tolerance_rad = angle_tolerance_rad
        self.orientation_free = orientation_free
        self.reach_m = reach_m
        self.from_first_joint_m = from_first_joint_m
        tol_mm = position_tolerance_m * 1e3
        tol_deg = math.degrees(angle_tolerance_rad)
        away_mm = _figure(distance_m * 1e3, tol_mm)
        what = "point" if orientation_free else "pose"
        if reach_m is not None:
            where = from_first_joint_m if from_first_joint_m is not None else math.nan
            message = (
                f"{what} unreachable: the target is {where:.3f} m from the arm's first joint, "
                f"which reaches {reach_m:.3f} m at most: every tool {what} is at least "
                f"{away_mm} mm away, over the {tol_mm:g} mm tolerance"
            )
        elif orientation_free:
            message = (
                f"point unreachable: the closest reachable tool point is {away_mm} mm away, "
                f"over the {tol_mm:g} mm tolerance"
            )
        else:
            away_deg = _figure(math.degrees(angle_rad), tol_deg)
            message = (
                f"pose unreachable: the closest reachable tool pose is {away_mm} mm and "
                f"{away_deg} deg away, over the {tol_mm:g} mm / {tol_deg:g} deg tolerance"
            )
        super().__init__(message)


def _figure(value: float, tolerance: float) -> str:
    """``value`` to 0.1, with more decimals when that would not show it is over ``tolerance``."""
    decimals = 1
    while decimals < 6 and value > tolerance and round(value, decimals) <= tolerance:
        decimals += 1
    return f"{value:.{decimals}f}"
