"""TrajectoryPlay: timed points played on the caller's clock, checked whole, braked on the path."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from support import examples

from c2rviz.motion.limits import MotionLimits, evaluate
from c2rviz.motion.path_play import TrajectoryPlay
from c2rviz.motion.trajectory import START_TOLERANCE, TrajectoryError, plan_trajectory

LIMITS = MotionLimits((2.0, 1.0), (4.0, 2.0), (40.0, 20.0), (-3.0, -0.5), (3.0, 2.0))
NAMES = ("shoulder", "slide")
UNITS = ("rad", "m")


WIDE = MotionLimits((1e3, 1e3), (1e4, 1e4), (1e5, 1e5), (-3.0, -0.5), (3.0, 2.0))
"""Limits no timing below breaks but the positions' (for properties of the path's shape)."""


def plan(times, positions, velocities=None, accelerations=None, start=(0.0, 0.0), limits=LIMITS):
    none = [None] * len(times)
    return plan_trajectory(
        start,
        times,
        positions,
        velocities or none,
        accelerations or none,
        limits,
        NAMES,
        UNITS,
    )


def derivative(planned, s: float, order: int) -> np.ndarray:
    return planned._derivative(s, order)


def test_it_starts_at_rest_and_passes_each_point_at_its_time() -> None:
    planned = plan([1.0, 2.0, 3.0], [[0.5, 0.2], [1.0, 0.1], [1.2, 0.0]])
    assert planned.sample(0.0).tolist() == [0.0, 0.0]
    for t, p in zip([1.0, 2.0, 3.0], [[0.5, 0.2], [1.0, 0.1], [1.2, 0.0]]):
        assert planned.sample(t) == pytest.approx(p, abs=1e-12)
    assert planned.sample(5.0).tolist() == [1.2, 0.0]  # exactly, at rest
    assert derivative(planned, 0.0, 1) == pytest.approx([0.0, 0.0])
    assert derivative(planned, 3.0, 1) == pytest.approx([0.0, 0.0])


def test_velocities_are_continuous_at_the_points() -> None:
    planned = plan([1.0, 2.0, 3.0], [[0.5, 0.2], [1.0, 0.1], [1.2, 0.0]])
    for knot in (1.0, 2.0):
        before = planned.coefficients[int(knot) - 1]
        after = planned.coefficients[int(knot)]
        tau = np.array([1.0])
        assert evaluate(before, tau, 1)[0] == pytest.approx(after[1], abs=1e-12)


def test_given_velocities_and_accelerations_are_met() -> None:
    planned = plan(
        [1.0, 2.0],
        [[0.5, 0.2], [1.0, 0.3]],
        velocities=[[0.6, 0.1], [0.0, 0.0]],
        accelerations=[[0.3, 0.0], [0.0, 0.0]],
    )
    assert derivative(planned, 1.0, 1) == pytest.approx([0.6, 0.1], abs=1e-9)
    assert derivative(planned, 1.0, 2) == pytest.approx([0.3, 0.0], abs=1e-9)
    assert derivative(planned, 2.0, 2) == pytest.approx([0.0, 0.0], abs=1e-9)


@settings(max_examples=examples(60), deadline=None)
@given(
    steps=st.lists(
        st.tuples(st.floats(0.5, 2.0), st.floats(-0.2, 0.2), st.floats(-0.05, 0.05)),
        min_size=1,
        max_size=6,
    )
)
@example(steps=[(0.5, 0.2, 0.0)])  # a step too quick for LIMITS' acceleration (a4c2ac1)
def test_without_velocities_the_path_never_overshoots_its_points(steps) -> None:
    times, positions, t, q = [], [], 0.0, np.zeros(2)
    for dt, dq0, dq1 in steps:
        t += dt
        q = q + [dq0, dq1]
        times.append(t)
        positions.append(q.copy())
    planned = plan(times, positions, limits=WIDE)
    knots = np.vstack([np.zeros(2), *positions])
    for k in range(len(times)):
        low, high = np.minimum(knots[k], knots[k + 1]), np.maximum(knots[k], knots[k + 1])
        for s in np.linspace(planned.times[k], planned.times[k + 1], 17):
            assert np.all(planned.sample(s) >= low - 1e-12)
            assert np.all(planned.sample(s) <= high + 1e-12)


REFUSED = [
    ([1.0], [[3.5, 0.0]], None, "points[0].positions: shoulder = 3.5 rad is outside its limits"),
    ([0.1], [[1.0, 0.0]], None, "on the way to points[0]: shoulder velocity reaches"),
    ([1.0], [[0.0, 0.6]], None, "on the way to points[0]: slide acceleration reaches"),
    ([1.0], [[0.5, 0.0]], [[1.0, 0.0]], "points[0].velocities are not 0 (shoulder: 1)"),
    ([0.0, 1.0], [[0.5, 0.0], [0.6, 0.0]], None, "points[0] is at time 0 but shoulder is 0.5"),
    (
        [1.0, 2.0],
        [[2.9, 0.0], [2.9, 0.0]],
        [[3.0, 0.0], [0.0, 0.0]],
        "on the way to points[",
    ),
]


@pytest.mark.parametrize(("times", "positions", "velocities", "text"), REFUSED)
def test_a_trajectory_breaking_a_limit_is_refused_naming_it(
    times, positions, velocities, text
) -> None:
    with pytest.raises(TrajectoryError) as refused:
        plan(times, positions, velocities)
    assert text in str(refused.value)


def test_a_point_at_time_zero_where_the_arm_is_is_the_start() -> None:
    near = [START_TOLERANCE / 2, 0.0]
    planned = plan([0.0, 2.0], [near, [0.4, 0.1]])
    assert planned.times.tolist() == [0.0, 2.0]
    assert planned.sample(0.0).tolist() == [0.0, 0.0]


def test_the_play_follows_the_clock_from_its_start() -> None:
    planned = plan([1.0, 2.0], [[0.5, 0.2], [1.0, 0.3]])
    play = TrajectoryPlay(planned, start=100.0)
    assert play.arrival == 102.0
    assert play.sample(99.0) == (0.0, 0.0)
    assert play.sample(101.0) == pytest.approx((0.5, 0.2))
    assert play.sample(102.0) == (1.0, 0.3)


def test_a_brake_stops_on_the_path_at_rest() -> None:
    planned = plan([2.0, 4.0], [[1.0, 0.2], [2.0, 0.4]])
    play = TrajectoryPlay(planned, start=0.0)
    arrival = play.brake(1.0)
    assert 1.0 < arrival < 4.0
    path = [play.path_time(t) for t in np.linspace(1.0, arrival, 50)]
    assert np.all(np.diff(path) >= -1e-12)  # never back along the path
    end = play.sample(arrival)
    assert play.sample(arrival + 5.0) == end  # at rest
    assert np.allclose(end, planned.sample(play.path_time(arrival)))  # on the path
    assert end[0] < 2.0  # short of the goal
    assert play.brake(2.0) == arrival  # a second stop changes nothing


def test_a_brake_near_the_end_lets_the_path_end_by_itself() -> None:
    planned = plan([1.0], [[0.5, 0.0]])
    play = TrajectoryPlay(planned, start=0.0)
    assert play.brake(0.99) == 1.0
