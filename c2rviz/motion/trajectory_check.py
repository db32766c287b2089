"""A planned trajectory's check against the limits (``trajectory.plan_trajectory``'s).

Every knot within its position limits; each segment sampled ``SAMPLES_PER_SEGMENT``
times besides its two knots, its positions within the limits and its velocities and
accelerations within the motion limits (``LIMIT_SLACK`` over them let through). The
segments are checked ``CHUNK`` at a time in array operations: thousands of points cost
a few Python steps, so the worker thread that checks holds the interpreter's lock
briefly (numpy lets it go in its large array operations) and the event loop goes on.
The first segment found is checked again alone, in the same arithmetic, to name its
worst value. Pure: numpy only.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..errors import LIMIT_TOLERANCE, C2rvizError, within_limit
from .limits import MotionLimits

__all__ = [
    "CHUNK",
    "FIRST_CHUNK",
    "LIMIT_SLACK",
    "SAMPLES_PER_SEGMENT",
    "TrajectoryError",
    "check_limits",
    "evaluate",
]

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
