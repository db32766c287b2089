"""How fast a chain may move: velocity, acceleration and jerk limits per joint.

URDF gives each joint a velocity limit but no acceleration or jerk limit, so
those are derived from the velocity (``ACCELERATION_PER_VELOCITY`` and
``JERK_PER_VELOCITY``); every value can be overridden, one number for all
joints or one per joint. Values are SI: [rad/s] or [m/s] and their derivatives.
``MotionPlanError``: ruckig could not plan a move within them.

A planned trajectory's check against the limits (``trajectory.plan_trajectory``'s):
every knot within its position limits; each segment sampled ``SAMPLES_PER_SEGMENT``
times besides its two knots, its positions within the limits and its velocities and
accelerations within the motion limits (``LIMIT_SLACK`` over them let through). The
segments are checked ``CHUNK`` at a time in array operations: thousands of points cost
a few Python steps, so the worker thread that checks holds the interpreter's lock
briefly (numpy lets it go in its large array operations) and the event loop goes on.
The first segment found is checked again alone, in the same arithmetic, to name its
worst value. Pure: numpy only.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import LIMIT_TOLERANCE, C2rvizError, within_limit
from ..robot.model import Robot

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


class MotionPlanError(C2rvizError):
    """ruckig could not plan the motion (numbers beyond its numerical range)."""

    def __init__(self, detail: str) -> None:
        self.detail = detail
        super().__init__(f"cannot plan the motion: {detail}")


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


LIMIT_SLACK = 1e-3
"""Relative slack over a velocity or acceleration limit (0.1 %): a trajectory timed
exactly at a limit by another planner passes despite rounding in its numbers."""
SAMPLES_PER_SEGMENT = 32
"""Instants checked inside each segment besides its two knots."""


class TrajectoryError(C2rvizError):
    """A trajectory refused whole: the message names the point, the joint and the limit."""


def evaluate(c: np.ndarray, tau: np.ndarray, order: int) -> np.ndarray:
    """Derivative ``order`` of the polynomial with coefficients ``c`` (6, joints) at ``tau``."""
    powers = np.arange(6)
    out = np.zeros((len(tau), c.shape[1]))
    for i in range(order, 6):
        factor = 1.0
        for j in range(order):
            factor *= i - j
        out += factor * np.outer(tau ** (powers[i] - order), c[i])
    return out


def _evaluate_all(c: np.ndarray, tau: np.ndarray, order: int) -> np.ndarray:
    """``evaluate`` of many segments at once, in the same arithmetic: ``c`` (segments, 6,
    joints), ``tau`` (segments, samples); shape (segments, samples, joints)."""
    powers = np.arange(6)
    out = np.zeros((*tau.shape, c.shape[2]))
    for i in range(order, 6):
        factor = 1.0
        for j in range(order):
            factor *= i - j
        out += factor * ((tau ** (powers[i] - order))[:, :, None] * c[:, None, i])
    return out


FIRST_CHUNK, CHUNK = 16, 1024
"""Segments checked at once (one array operation over all their instants): ``FIRST_CHUNK``
first, twice as many each time after, up to ``CHUNK``; a trajectory refused early (its
first point too far for its time) is refused after little work."""


def _within(values: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """``errors.within_limit`` of each value, the limits broadcast against them."""
    slack_low = LIMIT_TOLERANCE * np.maximum(1.0, np.abs(lower))
    slack_high = LIMIT_TOLERANCE * np.maximum(1.0, np.abs(upper))
    return (lower - slack_low <= values) & (values <= upper + slack_high)


def check_limits(
    times: np.ndarray,
    knots: np.ndarray,
    coefficients: np.ndarray,
    limits: MotionLimits,
    joint_names: Sequence[str],
    point_name: Callable[[int], str],
    units: Sequence[str],
) -> np.ndarray:
    """Refuse the first point outside its position limits, else the first segment that
    leaves a limit, naming its worst value. Segments are checked ``CHUNK`` at a time in
    array operations (a few Python steps for thousands of points: the worker thread holds
    the interpreter's lock that long); the segment found is checked again alone, in the
    same arithmetic, to name its worst value."""
    lower, upper = np.asarray(limits.lower), np.asarray(limits.upper)
    knots = knots[1:]  # the first is where the arm is
    outside = ~_within(knots, lower, upper)
    if outside.any():
        k, j = _worst(outside)
        value = float(knots[k, j])
        raise TrajectoryError(
            f"{point_name(k)}.positions: {joint_names[j]} = {value:.6g} {units[j]} "
            f"is outside its limits {lower[j]:.6g}..{upper[j]:.6g} {units[j]}"
        )
    velocity, acceleration = np.asarray(limits.velocity), np.asarray(limits.acceleration)
    most = 1 + LIMIT_SLACK
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_SEGMENT + 2)
    durations = np.diff(times)
    peak = np.zeros(len(lower))
    first, size = 0, FIRST_CHUNK
    while first < len(durations):
        c = coefficients[first : first + size]
        tau = fractions * durations[first : first + size, None]  # (segments, samples)
        positions = _evaluate_all(c, tau, 0)
        beyond = np.maximum(positions - upper, lower - positions).reshape(len(c), -1)
        worst = np.argmax(beyond, axis=1)
        value = positions.reshape(len(c), -1)[np.arange(len(c)), worst]
        bad = ~_within(value, lower[worst % len(lower)], upper[worst % len(lower)])
        rates = np.abs(_evaluate_all(c, tau, 1))
        bad |= (rates / velocity).max(axis=(1, 2)) > most
        bad |= (np.abs(_evaluate_all(c, tau, 2)) / acceleration).max(axis=(1, 2)) > most
        for segment in (first + np.flatnonzero(bad)).tolist():
            _check_segment(
                times, coefficients, segment, limits, joint_names, point_name(segment), units
            )
        peak = np.maximum(peak, rates.max(axis=(0, 1)))
        first, size = first + size, min(2 * size, CHUNK)
    return peak


def _check_segment(
    times: np.ndarray,
    coefficients: np.ndarray,
    k: int,
    limits: MotionLimits,
    joint_names: Sequence[str],
    point_name: str,
    units: Sequence[str],
) -> None:
    """Refuse segment ``k`` if it leaves a limit, naming its worst value."""
    lower, upper = np.asarray(limits.lower), np.asarray(limits.upper)
    c = coefficients[k]
    tau = np.linspace(0.0, 1.0, SAMPLES_PER_SEGMENT + 2) * float(times[k + 1] - times[k])
    where = f"on the way to {point_name}"
    positions = evaluate(c, tau, 0)
    i, j = _worst(np.maximum(positions - upper, lower - positions))
    value = float(positions[i, j])
    if not within_limit(value, float(lower[j]), float(upper[j])):
        raise TrajectoryError(
            f"{where}: {joint_names[j]} reaches {value:.6g} {units[j]} at "
            f"{times[k] + tau[i]:.6g} s, outside its limits "
            f"{lower[j]:.6g}..{upper[j]:.6g} {units[j]} (the path between points overshoots)"
        )
    for what, order, bound, per in (
        ("velocity", 1, np.asarray(limits.velocity), "/s"),
        ("acceleration", 2, np.asarray(limits.acceleration), "/s^2"),
    ):
        values = np.abs(evaluate(c, tau, order))
        ratio = values / bound
        i, j = _worst(ratio)
        if ratio[i, j] > 1 + LIMIT_SLACK:
            unit = units[j] + per
            raise TrajectoryError(
                f"{where}: {joint_names[j]} {what} reaches {values[i, j]:.6g} {unit} at "
                f"{times[k] + tau[i]:.6g} s, over its limit {bound[j]:.6g} {unit} "
                "(give the points more time)"
            )


def _worst(values: np.ndarray) -> tuple[int, int]:
    """(sample, joint) of the largest of ``values`` (samples x joints)."""
    i, j = np.unravel_index(int(np.argmax(values)), values.shape)
    return int(i), int(j)
