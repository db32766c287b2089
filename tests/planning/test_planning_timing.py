"""The timed path: on the polyline, within the limits, at the goal; braking stops on the path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from planning_scenes import distance_to_polyline, load

from c2rviz.motion import MotionLimits, motion_limits
from c2rviz.planning import BadPlanningSetting, TimedPath, time_path

DT = 1e-3  # [s] sampling step of the finite differences


def samples(path: TimedPath, dt: float = DT) -> tuple[np.ndarray, np.ndarray]:
    times = np.arange(path.start - 0.05, path.arrival + 0.05, dt)
    return times, np.array([path.sample(t) for t in times])


def random_polyline(limits: MotionLimits, corners: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    low, high = np.array(limits.lower), np.array(limits.upper)
    low, high = np.maximum(low, -2.5), np.minimum(high, 2.5)
    return rng.uniform(low, high, (corners, limits.n))


def assert_within_limits(path: TimedPath, limits: MotionLimits, speed: float) -> np.ndarray:
    """Positions, and velocities and accelerations by finite differences, within the limits."""
    _, qs = samples(path)
    assert np.all(qs >= np.array(limits.lower)) and np.all(qs <= np.array(limits.upper))
    velocity = np.diff(qs, axis=0) / DT
    acceleration = np.diff(velocity, axis=0) / DT
    jerk = np.array(limits.jerk) * speed**3
    assert np.all(np.abs(velocity) <= np.array(limits.velocity) * speed * (1 + 1e-6) + 1e-9)
    # a second difference averages the acceleration over 2 DT: within jerk * DT of it
    bound = np.array(limits.acceleration) * speed**2 + jerk * DT
    assert np.all(np.abs(acceleration) <= bound * (1 + 1e-6))
    return qs


@pytest.mark.parametrize("speed", [1.0, 0.5, 0.1])
@pytest.mark.parametrize("name", ["kuka_lwr", "fanuc_lrmate200id"])
def test_timed_path_stays_on_the_polyline_within_limits_and_arrives(
    name: str, speed: float
) -> None:
    limits = motion_limits(load(name))
    waypoints = random_polyline(limits, 4, seed=len(name))
    path = time_path(waypoints, limits, start=100.0, speed=speed)
    qs = assert_within_limits(path, limits, speed)
    assert distance_to_polyline(qs, waypoints).max() < 1e-9
    assert path.sample(path.arrival) == tuple(waypoints[-1])
    assert path.sample(path.start - 1.0) == tuple(waypoints[0])
    # it passes every corner, in order, at rest
    for corner, t in zip(waypoints[1:], path.reach_times()):
        assert np.allclose(path.sample(t), corner, atol=1e-9)
        assert np.allclose(path.state(t)[1], 0.0, atol=1e-9)


def test_slower_speed_is_the_same_path_played_slower() -> None:
    limits = motion_limits(load("kuka_lwr"))
    waypoints = random_polyline(limits, 3, seed=2)
    fast = time_path(waypoints, limits, start=0.0)
    slow = time_path(waypoints, limits, start=0.0, speed=0.25)
    assert slow.duration == pytest.approx(fast.duration / 0.25, rel=1e-6)
    for f in np.linspace(0, 1, 23):
        assert np.allclose(slow.sample(f * slow.duration), fast.sample(f * fast.duration))


@pytest.mark.parametrize("fraction", [0.05, 0.2, 0.37, 0.5, 0.81, 0.999])
def test_brake_stops_on_the_edge_being_played(fraction: float) -> None:
    limits = motion_limits(load("kuka_lwr"))
    waypoints = random_polyline(limits, 4, seed=9)
    path = time_path(waypoints, limits, start=5.0, speed=0.7)
    reached = [path.start, *path.reach_times()]
    when = path.start + fraction * path.duration
    edge = int(np.searchsorted(reached, when, side="right")) - 1
    before = path.state(when)
    rest = path.brake(when)
    assert rest >= when and path.arrival == rest
    assert np.allclose(path.state(when)[0], before[0]) and np.allclose(
        path.state(when)[1], before[1]
    )  # the brake takes over without a jump in position or velocity
    stop = np.array(path.sample(rest + 1.0))
    a, b = waypoints[edge], waypoints[edge + 1]
    along = np.dot(stop - a, b - a) / np.dot(b - a, b - a)
    assert -1e-12 <= along <= 1 + 1e-12
    assert np.linalg.norm(stop - (a + along * (b - a))) < 1e-9
    assert_within_limits(path, limits, 1.0)  # a brake may use the joints' full limits
    assert path.brake(rest + 1.0) == rest  # at rest: nothing changes


def test_a_brake_uses_the_full_limits_whatever_the_speed() -> None:
    """Issue 23.2: a stop at 5 % speed is as quick as the joints allow, not 400 times slower."""
    limits = motion_limits(load("kuka_lwr"))
    waypoints = random_polyline(limits, 2, seed=4)
    rests = []
    for speed in (1.0, 0.05):
        path = time_path(waypoints, limits, start=0.0, speed=speed)
        when = 0.5 * path.duration
        state = path.state(when)
        rests.append(path.brake(when) - when)
        assert np.allclose(path.state(when)[1], state[1])
    assert rests[1] < rests[0]  # the slow path, moving slower, stops sooner


def test_one_waypoint_or_repeated_corners_take_no_time() -> None:
    limits = motion_limits(load("fanuc_lrmate200id"))
    q = np.zeros(6)
    assert time_path(q[None, :], limits, start=3.0).duration == 0.0
    path = time_path(np.array([q, q, q + 0.1, q + 0.1]), limits, start=3.0)
    assert len(path.reach_times()) == 1 and path.sample(path.arrival) == tuple(q + 0.1)


@pytest.mark.parametrize(
    ("waypoints", "speed", "key"),
    [
        (np.zeros((2, 5)), 1.0, "waypoints"),
        (np.zeros((0, 6)), 1.0, "waypoints"),
        (np.full((2, 6), math.nan), 1.0, "waypoints"),
        (np.full((2, 6), 100.0), 1.0, "waypoints"),
        (np.zeros((2, 6)), 0.0, "speed"),
        (np.zeros((2, 6)), 1.5, "speed"),
        (np.zeros((2, 6)), math.nan, "speed"),
    ],
    ids=["columns", "empty", "nan", "outside limits", "speed 0", "speed 1.5", "speed nan"],
)
def test_bad_input_is_refused(waypoints: np.ndarray, speed: float, key: str) -> None:
    limits = motion_limits(load("fanuc_lrmate200id"))
    with pytest.raises(BadPlanningSetting, match=rf"^{key} = "):
        time_path(waypoints, limits, start=0.0, speed=speed)
