"""What the IK is asked for: a full tool pose, or a tool point with its orientation free.

A full pose is a ``pin.SE3`` (as before); ``PointTarget`` asks only for the
tool point's position, leaving its orientation to the solver (it stays near
the seed's). Both are in the robot's base frame, as ``Robot.ee_pose`` gives.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import pinocchio as pin

__all__ = ["Goal", "PointTarget", "Target", "goal_in_world"]


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
