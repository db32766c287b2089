"""How fast a chain may move: velocity, acceleration and jerk limits per joint.

URDF gives each joint a velocity limit but no acceleration or jerk limit, so
those are derived from the velocity (``ACCELERATION_PER_VELOCITY`` and
``JERK_PER_VELOCITY``); every value can be overridden, one number for all
joints or one per joint. Values are SI: [rad/s] or [m/s] and their derivatives.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import C2rvizError
from ..robot.model import Robot

__all__ = [
    "LIMIT_RANGE",
    "ACCELERATION_PER_VELOCITY",
    "DEFAULT_PRISMATIC_VELOCITY",
    "DEFAULT_REVOLUTE_VELOCITY",
    "JERK_PER_VELOCITY",
    "MotionLimitError",
    "MotionLimits",
    "motion_limits",
]

DEFAULT_REVOLUTE_VELOCITY = 1.0  # [rad/s] where the URDF gives none, 0 or unbounded
DEFAULT_PRISMATIC_VELOCITY = 0.25  # [m/s] likewise for a prismatic joint
ACCELERATION_PER_VELOCITY = 2.0  # [1/s]: default acceleration = 2 * velocity limit
JERK_PER_VELOCITY = 10.0  # [1/s^2]: default jerk = 10 * velocity limit
# With these defaults a joint reaches full speed from rest in 0.7 s: 0.2 s jerk
# ramps at both ends of 0.3 s at full acceleration; a visible, smooth start.
_UNBOUNDED = 1e10  # Pinocchio's stand-in for "no limit"


class MotionLimitError(C2rvizError):
    """A bad motion limit, speed or target; the message names the key."""

    def __init__(self, key: str, problem: str) -> None:
        self.key = key
        self.problem = problem
        super().__init__(f"{key}: {problem}")


LIMIT_RANGE = (1e-6, 1e9)
"""Every velocity, acceleration and jerk limit lies in this range (per s, s^2, s^3): a
limit of 1e-300 passes "> 0" and then plans a move of 1e300 s, which ruckig refuses."""


def _positive(key: str, values: Sequence[float], n: int) -> tuple[float, ...]:
    """``values`` as floats, or MotionLimitError unless ``n`` finite numbers in LIMIT_RANGE."""
    if len(values) != n:
        raise MotionLimitError(key, f"{len(values)} values for {n} joints; give 1 or {n}")
    low, high = LIMIT_RANGE
    for i, value in enumerate(values):
        if isinstance(value, bool) or not (
            isinstance(value, numbers.Real) and math.isfinite(value) and value > 0
        ):
            raise MotionLimitError(key, f"joint {i} is {value!r}; it must be a finite number > 0")
        if not low <= value <= high:
            raise MotionLimitError(
                key, f"joint {i} is {value!r}; it must be within {low:g}..{high:g}"
            )
    return tuple(float(value) for value in values)


@dataclass(frozen=True, slots=True)
class MotionLimits:
    """Limits of each chain joint, SI.

    Attributes:
        velocity: Maximum speed [rad/s or m/s] at speed fraction 1.
        acceleration: Maximum acceleration [rad/s^2 or m/s^2] at speed fraction 1.
        jerk: Maximum jerk [rad/s^3 or m/s^3] at speed fraction 1.
        lower: Lower position limit [rad or m] (a continuous joint's is finite too:
            ``-robot.CONTINUOUS_LIMIT``; ``-inf`` is allowed for no limit).
        upper: Upper position limit [rad or m].

    Raises:
        MotionLimitError: a count that differs from ``len(velocity)``, a
            velocity, acceleration or jerk that is not a finite number > 0, or
            position limits that are NaN or reversed (names the field).
    """

    velocity: tuple[float, ...]
    acceleration: tuple[float, ...]
    jerk: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]

    def __post_init__(self) -> None:
        n = len(self.velocity)
        if n == 0:
            raise MotionLimitError("velocity", "no joints; give one value per chain joint")
        for key in ("velocity", "acceleration", "jerk"):
            object.__setattr__(self, key, _positive(key, getattr(self, key), n))
        for key in ("lower", "upper"):
            count = len(getattr(self, key))
            if count != n:
                raise MotionLimitError(key, f"{count} values for {n} joints")
            object.__setattr__(self, key, tuple(float(x) for x in getattr(self, key)))
        for i, (low, high) in enumerate(zip(self.lower, self.upper)):
            if not low <= high:  # also refuses NaN
                raise MotionLimitError("lower", f"joint {i} has limits {low}..{high}")

    @property
    def n(self) -> int:
        """Number of chain joints."""
        return len(self.velocity)


def _override(
    key: str, value: float | Sequence[float] | None, default: Sequence[float], n: int
) -> tuple[float, ...]:
    if value is None:
        return tuple(default)
    values = list(value) if isinstance(value, (Sequence, np.ndarray)) else [value] * n
    return _positive(key, values, n)


def motion_limits(
    robot: Robot,
    max_velocity: float | Sequence[float] | None = None,
    max_acceleration: float | Sequence[float] | None = None,
    max_jerk: float | Sequence[float] | None = None,
) -> MotionLimits:
    """The motion limits of ``robot``'s chain, from its URDF unless overridden.

    Velocity comes from each joint's URDF ``<limit velocity>`` (Pinocchio's
    ``model.velocityLimit``); where that is missing, 0 or unbounded,
    ``DEFAULT_REVOLUTE_VELOCITY`` [rad/s] or ``DEFAULT_PRISMATIC_VELOCITY``
    [m/s]. Acceleration and jerk default to ``ACCELERATION_PER_VELOCITY`` and
    ``JERK_PER_VELOCITY`` times the (possibly overridden) velocity. Position
    limits are the chain's.

    Args:
        robot: The robot whose chain moves.
        max_velocity: One number for every joint, or one per joint [rad/s or m/s].
        max_acceleration: Likewise [rad/s^2 or m/s^2].
        max_jerk: Likewise [rad/s^3 or m/s^3].

    Raises:
        MotionLimitError: a value that is not a finite number > 0, or a count
            that is neither 1 nor the number of chain joints; names the key.
    """
    model, n = robot.model, robot.n
    urdf = []
    for joint in robot.joints:
        limit = float(model.velocityLimit[model.joints[model.getJointId(joint.name)].idx_v])
        if not 0 < limit < _UNBOUNDED:
            limit = DEFAULT_PRISMATIC_VELOCITY if joint.prismatic else DEFAULT_REVOLUTE_VELOCITY
        elif limit < LIMIT_RANGE[0] and max_velocity is None:
            raise MotionLimitError(
                "velocity",
                f"{joint.name}'s URDF velocity limit {limit:g} is below {LIMIT_RANGE[0]:g}: "
                "give it a real limit in the URDF, or one with --max-velocity",
            )
        urdf.append(limit)
    velocity = _override("max_velocity", max_velocity, urdf, n)
    acceleration = _override(
        "max_acceleration", max_acceleration, [ACCELERATION_PER_VELOCITY * v for v in velocity], n
    )
    jerk = _override("max_jerk", max_jerk, [JERK_PER_VELOCITY * v for v in velocity], n)
    return MotionLimits(velocity, acceleration, jerk, robot.lower, robot.upper)
