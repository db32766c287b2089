"""What the IK is asked for: a full tool pose, or a tool point with its orientation free.

A full pose is a ``pin.SE3`` (as before); ``PointTarget`` asks only for the
tool point's position, leaving its orientation to the solver (it stays near
the seed's). Both are in the robot's base frame, as ``Robot.ee_pose`` gives.

``Unreachable`` is the IK's refusal of a target: how close the tool could get, beside
the tolerance it missed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError

__all__ = ["Goal", "PointTarget", "Target", "Unreachable", "goal_in_world"]


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
