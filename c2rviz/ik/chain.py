"""The chain as the IK solves it: a Pinocchio model of the chain alone, with a tool.

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
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ..errors import JointCountError
from ..robot.model import Robot

__all__ = ["IkChain", "ReachBound", "TOOL_FRAME", "chain_model"]


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
