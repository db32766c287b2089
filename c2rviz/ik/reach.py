"""How far the tool point can ever be from the arm's first joint: a bound computed once.

Walk the chain from the tool frame up to the first joint. A revolute joint
turns about its own origin, so the distance from one joint's origin to the
next is fixed (the length of the next joint's placement); a prismatic joint
adds at most its longest travel. By the triangle inequality the tool point
stays within the sum of those lengths (and the tool offset) of the first
joint's origin, which is fixed in the model's world frame. A target farther
than that is refused before any solve.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from .chain import IkChain

__all__ = ["ReachBound"]


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
