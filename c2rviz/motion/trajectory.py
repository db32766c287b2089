"""Timed joint points (a ROS ``JointTrajectory``'s) planned as a path in time, checked whole.

The trajectory starts where the arm is, at rest, at path time 0, and passes
each point at its ``time_from_start`` [s]. Between two knots each joint follows
a polynomial in time:

* quintic when both knots carry accelerations (positions, velocities and
  accelerations are met at both ends), else cubic Hermite (positions and
  velocities met);
* a point without velocities gets them estimated as PCHIP does (the weighted
  harmonic mean of the neighbouring slopes, 0 where the path turns): the path
  then never overshoots its points, so a trajectory whose points are within the
  position limits stays within them;
* the start knot is the arm at rest; the last point must be at rest too (its
  velocities and accelerations 0 or left out), as a ``PathPlay`` ends at rest.

``plan_trajectory`` checks the whole before anything moves (``TrajectoryError``
names the point, the joint and the limit): every joint's position within its
limits, and its velocity and acceleration within the robot's motion limits at
full speed (``MotionLimits``; ``LIMIT_SLACK`` over them is let through), each
sampled ``SAMPLES_PER_SEGMENT`` times per segment and at every knot. A point at
time 0 must be where the arm is (within ``START_TOLERANCE``): it is the start.
``path_play.TrajectoryPlay`` plays the result. Pure: numpy only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import C2rvizError
from ..tolerance import within_limit
from .limits import MotionLimits

__all__ = [
    "LIMIT_SLACK",
    "SAMPLES_PER_SEGMENT",
    "START_TOLERANCE",
    "PlannedTrajectory",
    "TrajectoryError",
    "Values",
    "plan_trajectory",
]

LIMIT_SLACK = 1e-3
"""Relative slack over a velocity or acceleration limit (0.1 %): a trajectory timed
exactly at a limit by another planner passes despite rounding in its numbers."""
SAMPLES_PER_SEGMENT = 32
"""Instants checked inside each segment besides its two knots."""
START_TOLERANCE = 1e-3
"""How far [rad or m] a point at time 0 may be from where the arm is."""


class TrajectoryError(C2rvizError):
    """A trajectory refused whole: the message names the point, the joint and the limit."""


@dataclass(frozen=True)
class PlannedTrajectory:
    """A checked trajectory: knot times and each segment's polynomial coefficients.

    Attributes:
        times: Knot times [s] from the start: 0, then each point's.
        knots: The positions at those times [rad or m], one row each.
        coefficients: Shape (segments, 6, joints): ``q(t) = sum c[i] (t - times[k])**i``.
        peak_rate: Each joint's largest speed along the path [rad/s or m/s] (for braking).
        limits: The limits it was checked against.
    """

    times: np.ndarray
    knots: np.ndarray
    coefficients: np.ndarray
    peak_rate: np.ndarray
    limits: MotionLimits

    @property
    def duration(self) -> float:
        """Time from the start to the last point [s]."""
        return float(self.times[-1])

    def sample(self, s: float) -> np.ndarray:
        """Positions [rad or m] at path time ``s`` [s]: the first or last knot exactly
        before the start and from the end on."""
        if s <= 0.0:
            return self.knots[0].copy()
        if s >= self.times[-1]:
            return self.knots[-1].copy()
        return self._derivative(s, 0)

    def _derivative(self, s: float, order: int) -> np.ndarray:
        times = self.times
        s = min(max(s, 0.0), float(times[-1]))
        k = min(int(np.searchsorted(times, s, side="right")) - 1, len(times) - 2)
        tau = s - float(times[k])
        c = self.coefficients[k]
        return _evaluate(c, np.array([tau]), order)[0]


def _evaluate(c: np.ndarray, tau: np.ndarray, order: int) -> np.ndarray:
    """Derivative ``order`` of the polynomial with coefficients ``c`` (6, joints) at ``tau``."""
    powers = np.arange(6)
    out = np.zeros((len(tau), c.shape[1]))
    for i in range(order, 6):
        factor = 1.0
        for j in range(order):
            factor *= i - j
        out += factor * np.outer(tau ** (powers[i] - order), c[i])
    return out


def _pchip_velocities(times: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Velocities at the inner knots that keep each segment between its knots (PCHIP)."""
    h = np.diff(times)[:, None]
    slopes = np.diff(q, axis=0) / h
    v = np.zeros_like(q)
    before, after = slopes[:-1], slopes[1:]
    h0, h1 = h[:-1], h[1:]
    w1, w2 = 2 * h1 + h0, h1 + 2 * h0
    same = (before * after) > 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        mean = (w1 + w2) / (w1 / before + w2 / after)
    v[1:-1] = np.where(same, mean, 0.0)
    return v


def _coefficients(
    h: float,
    p0: np.ndarray,
    v0: np.ndarray,
    a0: np.ndarray | None,
    p1: np.ndarray,
    v1: np.ndarray,
    a1: np.ndarray | None,
) -> np.ndarray:
    c = np.zeros((6, len(p0)))
    c[0], c[1] = p0, v0
    dp = p1 - p0
    if a0 is not None and a1 is not None:  # quintic: positions, velocities, accelerations
        c[2] = a0 / 2
        c[3] = (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3)
        c[4] = (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4)
        c[5] = (12 * dp - 6 * (v1 + v0) * h - (a0 - a1) * h**2) / (2 * h**5)
    else:  # cubic Hermite: positions and velocities
        c[2] = (3 * dp / h - 2 * v0 - v1) / h
        c[3] = (-2 * dp / h + v0 + v1) / h**2
    return c


Values = Sequence[float] | np.ndarray
"""One value per chain joint."""


def plan_trajectory(
    start: Values,
    times: Sequence[float],
    positions: Sequence[Values],
    velocities: Sequence[Values | None],
    accelerations: Sequence[Values | None],
    limits: MotionLimits,
    joint_names: Sequence[str],
    units: Sequence[str] | None = None,
    point_names: Sequence[str] | None = None,
) -> PlannedTrajectory:
    """Plan a trajectory from ``start`` (at rest) through timed points, and check it whole.

    Args:
        start: The chain where the arm is [rad or m].
        times: Each point's time from the start [s], each >= 0, strictly increasing.
        positions: Each point's whole chain [rad or m].
        velocities: Each point's chain velocities [rad/s or m/s], or None to estimate.
        accelerations: Each point's chain accelerations [rad/s^2 or m/s^2], or None.
        limits: Position, velocity and acceleration limits of the chain.
        joint_names: The chain's joint names (for messages).
        units: Each joint's unit, ``rad`` or ``m`` (for messages; default ``rad``).
        point_names: How a message names each point (default ``points[i]``).

    Returns:
        The planned trajectory.

    Raises:
        TrajectoryError: A point at time 0 away from the start, a last point not at
            rest, or a position, velocity or acceleration past a limit anywhere.
    """
    names = list(point_names or [f"points[{i}]" for i in range(len(times))])
    q_start = np.asarray(start, dtype=float)
    t = [float(x) for x in times]
    q = [np.asarray(p, dtype=float) for p in positions]
    v: list[np.ndarray | None] = [None if x is None else np.asarray(x, float) for x in velocities]
    a: list[np.ndarray | None] = [
        None if x is None else np.asarray(x, float) for x in accelerations
    ]
    if t and t[0] == 0.0:
        far = np.abs(q[0] - q_start)
        j = int(np.argmax(far))
        if far[j] > START_TOLERANCE:
            raise TrajectoryError(
                f"{names[0]} is at time 0 but {joint_names[j]} is {far[j]:.6g} away from where "
                f"the arm is (at most {START_TOLERANCE:g}): a point at time 0 is the start"
            )
        t, q, v, a, names = t[1:], q[1:], v[1:], a[1:], names[1:]
        if not t:
            return _plan([0.0, 1e-9], [q_start, q_start], [None, None], [None, None], limits)
    for what, last in (("velocities", v[-1]), ("accelerations", a[-1])):
        if last is not None and np.any(np.abs(last) > 1e-9):
            j = int(np.argmax(np.abs(last)))
            raise TrajectoryError(
                f"{names[-1]}.{what} are not 0 ({joint_names[j]}: {last[j]:.6g}): "
                "a trajectory ends at rest"
            )
    planned = _plan([0.0, *t], [q_start, *q], [np.zeros_like(q_start), *v], [None, *a], limits)
    _check(planned, limits, joint_names, names, units or ["rad"] * len(q_start))
    return planned


def _plan(
    times: Sequence[float],
    q: Sequence[np.ndarray],
    v: Sequence[np.ndarray | None],
    a: Sequence[np.ndarray | None],
    limits: MotionLimits,
) -> PlannedTrajectory:
    knots = np.asarray(times, dtype=float)
    qs = np.vstack(q)
    estimated = _pchip_velocities(knots, qs)  # 0 at both ends
    velocities = [estimated[k] if given is None else given for k, given in enumerate(v)]
    accelerations = list(a)
    accelerations[0] = np.zeros(qs.shape[1])  # the start is at rest
    coefficients = np.stack(
        [
            _coefficients(
                float(knots[k + 1] - knots[k]),
                qs[k],
                velocities[k],
                accelerations[k],
                qs[k + 1],
                velocities[k + 1],
                accelerations[k + 1],
            )
            for k in range(len(knots) - 1)
        ]
    )
    return PlannedTrajectory(knots, qs, coefficients, np.zeros(qs.shape[1]), limits)


def _check(
    planned: PlannedTrajectory,
    limits: MotionLimits,
    joint_names: Sequence[str],
    point_names: Sequence[str],
    units: Sequence[str],
) -> None:
    """Refuse the first segment that leaves a limit, naming its worst value."""
    lower, upper = np.asarray(limits.lower), np.asarray(limits.upper)
    bounds = (
        ("velocity", 1, np.asarray(limits.velocity), "/s"),
        ("acceleration", 2, np.asarray(limits.acceleration), "/s^2"),
    )
    knots = planned.knots  # the first is where the arm is
    for k in range(1, len(knots)):
        for j, value in enumerate(knots[k].tolist()):
            if not within_limit(value, float(lower[j]), float(upper[j])):
                raise TrajectoryError(
                    f"{point_names[k - 1]}.positions: {joint_names[j]} = {value:.6g} {units[j]} "
                    f"is outside its limits {lower[j]:.6g}..{upper[j]:.6g} {units[j]}"
                )
    peak = np.zeros(len(lower))
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_SEGMENT + 2)
    for k, c in enumerate(planned.coefficients):
        tau = fractions * float(planned.times[k + 1] - planned.times[k])
        where = f"on the way to {point_names[k]}"
        positions = _evaluate(c, tau, 0)
        beyond = np.maximum(positions - upper, lower - positions)
        i, j = _worst(beyond)
        value = float(positions[i, j])
        if not within_limit(value, float(lower[j]), float(upper[j])):
            raise TrajectoryError(
                f"{where}: {joint_names[j]} reaches {value:.6g} {units[j]} at "
                f"{planned.times[k] + tau[i]:.6g} s, outside its limits "
                f"{lower[j]:.6g}..{upper[j]:.6g} {units[j]} (the path between points overshoots)"
            )
        for what, order, bound, per in bounds:
            values = np.abs(_evaluate(c, tau, order))
            if order == 1:
                peak = np.maximum(peak, values.max(axis=0))
            ratio = values / bound
            i, j = _worst(ratio)
            if ratio[i, j] > 1 + LIMIT_SLACK:
                unit = units[j] + per
                raise TrajectoryError(
                    f"{where}: {joint_names[j]} {what} reaches {values[i, j]:.6g} {unit} at "
                    f"{planned.times[k] + tau[i]:.6g} s, over its limit {bound[j]:.6g} {unit} "
                    "(give the points more time)"
                )
    planned.peak_rate[:] = peak


def _worst(values: np.ndarray) -> tuple[int, int]:
    """(sample, joint) of the largest of ``values`` (samples x joints)."""
    i, j = np.unravel_index(int(np.argmax(values)), values.shape)
    return int(i), int(j)
