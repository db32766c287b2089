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

from .limits import (
    MotionLimits,
    TrajectoryError,
    check_limits,
    evaluate,
)

START_TOLERANCE = 1e-3
"""How far [rad or m] a point at time 0 may be from where the arm is."""


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
        return evaluate(c, np.array([tau]), order)[0]


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
    h: np.ndarray,
    p0: np.ndarray,
    v0: np.ndarray,
    a0: np.ndarray,
    p1: np.ndarray,
    v1: np.ndarray,
    a1: np.ndarray,
    quintic: np.ndarray,
) -> np.ndarray:
    """Every segment's coefficients at once, shape (segments, 6, joints): ``h`` (segments, 1)
    the durations, the others (segments, joints); ``quintic`` (segments,) where both knots
    carry accelerations (positions, velocities and accelerations met), else cubic Hermite
    (positions and velocities met)."""
    c = np.zeros((len(h), 6, p0.shape[1]))
    c[:, 0], c[:, 1] = p0, v0
    dp = p1 - p0
    c[:, 2] = (3 * dp / h - 2 * v0 - v1) / h
    c[:, 3] = (-2 * dp / h + v0 + v1) / h**2
    if quintic.any():
        h, dp, v0, v1, a0, a1 = (x[quintic] for x in (h, dp, v0, v1, a0, a1))
        c[quintic, 2] = a0 / 2
        c[quintic, 3] = (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3)
        c[quintic, 4] = (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4)
        c[quintic, 5] = (12 * dp - 6 * (v1 + v0) * h - (a0 - a1) * h**2) / (2 * h**5)
    return c


def _rows(values: Sequence[Values | None], n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points' optional values as one array (0 where left out) and where they were given."""
    out = np.zeros((len(values), n))
    given = np.fromiter((x is not None for x in values), bool, len(values))
    if given.any():
        out[given] = np.asarray([x for x in values if x is not None], dtype=float)
    return out, given


Values = Sequence[float] | np.ndarray
"""One value per chain joint."""


def plan_trajectory(
    start: Values,
    times: Sequence[float],
    positions: Sequence[Values] | np.ndarray,
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
        positions: Each point's whole chain [rad or m] (a row each).
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

    def name(i: int) -> str:  # made only for a message: thousands of points cost nothing
        return f"points[{i}]" if point_names is None else point_names[i]

    q_start = np.asarray(start, dtype=float)
    n = len(q_start)
    t = np.asarray(times, dtype=float)
    q = np.asarray(positions, dtype=float).reshape(len(t), n)
    v, v_given = _rows(velocities, n)
    a, a_given = _rows(accelerations, n)
    if len(t) and t[0] == 0.0:
        far = np.abs(q[0] - q_start)
        j = int(np.argmax(far))
        if far[j] > START_TOLERANCE:
            raise TrajectoryError(
                f"{name(0)} is at time 0 but {joint_names[j]} is {far[j]:.6g} away from where "
                f"the arm is (at most {START_TOLERANCE:g}): a point at time 0 is the start"
            )
        t, q, v, v_given, a, a_given = (x[1:] for x in (t, q, v, v_given, a, a_given))
        if not len(t):
            at_rest = np.zeros((2, n))
            none = np.zeros(2, bool)
            return _plan(np.array([0.0, 1e-9]), np.vstack([q_start, q_start]), at_rest, none,
                         at_rest, none, limits)  # fmt: skip
    for what, last, given in (
        ("velocities", v[-1], v_given[-1]),
        ("accelerations", a[-1], a_given[-1]),
    ):
        if given and np.any(np.abs(last) > 1e-9):
            j = int(np.argmax(np.abs(last)))
            raise TrajectoryError(
                f"{name(len(times) - 1)}.{what} are not 0 ({joint_names[j]}: {last[j]:.6g}): "
                "a trajectory ends at rest"
            )
    rest, yes = np.zeros((1, n)), np.ones(1, bool)
    planned = _plan(
        np.concatenate([[0.0], t]),
        np.vstack([q_start, q]),
        np.vstack([rest, v]),
        np.concatenate([yes, v_given]),
        np.vstack([rest, a]),
        np.concatenate([yes, a_given]),
        limits,
    )
    planned.peak_rate[:] = check_limits(
        planned.times, planned.knots, planned.coefficients, limits, joint_names,
        lambda k: name(k + len(times) - len(t)),
        units or ["rad"] * n,
    )  # fmt: skip
    return planned


def _plan(
    knots: np.ndarray,
    qs: np.ndarray,
    v: np.ndarray,
    v_given: np.ndarray,
    a: np.ndarray,
    a_given: np.ndarray,
    limits: MotionLimits,
) -> PlannedTrajectory:
    """The knots' polynomials: velocities left out estimated (PCHIP), the start at rest."""
    velocities = np.where(v_given[:, None], v, _pchip_velocities(knots, qs))  # 0 at both ends
    a_given = a_given.copy()
    a_given[0] = True  # the start is at rest (its row is 0)
    coefficients = _coefficients(
        np.diff(knots)[:, None],
        qs[:-1],
        velocities[:-1],
        a[:-1],
        qs[1:],
        velocities[1:],
        a[1:],
        a_given[:-1] & a_given[1:],
    )
    return PlannedTrajectory(knots, qs, coefficients, np.zeros(qs.shape[1]), limits)
