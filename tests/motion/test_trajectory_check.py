"""A trajectory of thousands of points planned and checked in array operations: the same
answers as one segment at a time (the segment refused, the knots met, the peak rate)."""

from __future__ import annotations

import numpy as np
import pytest

from c2rviz.motion.limits import (
    CHUNK,
    FIRST_CHUNK,
    SAMPLES_PER_SEGMENT,
    MotionLimits,
    TrajectoryError,
    evaluate,
)
from c2rviz.motion.trajectory import plan_trajectory

LIMITS = MotionLimits((2.0, 1.0), (4.0, 2.0), (40.0, 20.0), (-3.0, -0.5), (3.0, 2.0))
NAMES = ("shoulder", "slide")
POINTS = 3 * CHUNK


def slow(points: int = POINTS) -> tuple[list[float], np.ndarray]:
    """A gentle sweep: 0.1 s a point, each 1e-4 from the last."""
    times = [0.1 * (i + 1) for i in range(points)]
    positions = np.array([[1e-4 * (i + 1), 0.0] for i in range(points)])
    positions[-1] = positions[-2]  # then a pause
    return times, positions


def plan(times, positions, velocities=None, accelerations=None):
    none = [None] * len(times)
    return plan_trajectory(
        (0.0, 0.0), times, positions, velocities or none, accelerations or none, LIMITS, NAMES
    )


@pytest.mark.parametrize("k", [0, FIRST_CHUNK - 1, FIRST_CHUNK, CHUNK + 7, POINTS - 2])
def test_the_first_segment_too_fast_is_named_wherever_it_lies(k: int) -> None:
    times, positions = slow()
    positions[k + 1 :, 0] += 0.5  # half a radian in 0.1 s: 5 rad/s or more
    with pytest.raises(
        TrajectoryError, match=rf"^on the way to points\[{k + 1}\]: shoulder velocity"
    ):
        plan(times, positions)


def test_the_first_point_outside_its_limits_is_named_before_any_segment() -> None:
    times, positions = slow()
    positions[5:, 0] += 0.5  # too fast from point 5 on
    positions[CHUNK + 3, 1] = 2.5  # past the slide's 2.0 (and far too fast)
    with pytest.raises(TrajectoryError, match=rf"^points\[{CHUNK + 3}\]\.positions: slide = 2\.5"):
        plan(times, positions)


def test_each_segment_meets_its_knots_and_the_peak_rate_is_the_largest_sampled() -> None:
    times, positions = slow(CHUNK + 40)
    rng = np.random.default_rng(3)
    velocities = [rng.uniform(0, 0.02, 2) if i % 3 else None for i in range(len(times))]
    accelerations = [rng.uniform(0, 0.02, 2) if i % 5 < 2 else None for i in range(len(times))]
    velocities[-1] = accelerations[-1] = None  # it ends at rest
    planned = plan(times, positions, velocities, accelerations)
    peak = np.zeros(2)
    fractions = np.linspace(0.0, 1.0, SAMPLES_PER_SEGMENT + 2)
    for k, c in enumerate(planned.coefficients):
        h = planned.times[k + 1] - planned.times[k]
        ends = np.array([0.0, h])
        assert evaluate(c, ends, 0) == pytest.approx(planned.knots[k : k + 2], abs=1e-12)
        for order, given in ((1, velocities), (2, accelerations)):
            at = evaluate(c, ends, order)
            for end, point in ((0, k - 1), (1, k)):  # point -1 is the start, at rest
                if point < 0:
                    assert at[end] == pytest.approx([0.0, 0.0], abs=1e-9)
                elif given[point] is not None and (order == 1 or _quintic(k, accelerations)):
                    assert at[end] == pytest.approx(given[point], abs=1e-9)
        if not _quintic(k, accelerations):
            assert not c[4:].any()  # a cubic Hermite
        peak = np.maximum(peak, np.abs(evaluate(c, fractions * h, 1)).max(axis=0))
    assert planned.peak_rate.tolist() == peak.tolist()


def _quintic(k: int, accelerations: list) -> bool:
    """Segment ``k`` (from point k-1, or the start, to point k) meets accelerations."""
    return (k == 0 or accelerations[k - 1] is not None) and accelerations[k] is not None
