"""A straight line's joint path played in time: eased in and out, braked on the path.

Pure: ``LinePlay`` is sampled every millisecond on a made-up clock, with the
motoman's real limits, and finite differences of what it gives are held
against those limits.
"""

from __future__ import annotations

import numpy as np
import pytest
from support import load_robot

from c2rviz.motion.limits import motion_limits
from c2rviz.motion.path_play import LinePlay, ramp_limits

DT = 1e-3  # sampling step [s]
LIMITS = motion_limits(load_robot("motoman_sia20d"))
VELOCITY = np.array(LIMITS.velocity)
ACCELERATION = np.array(LIMITS.acceleration)
JERK = np.array(LIMITS.jerk)


def one_segment(fraction: float, start: float = 10.0) -> tuple[LinePlay, np.ndarray]:
    """A path of one segment, timed so its fastest joint moves at its velocity limit."""
    qs = np.array([[0.0] * 7, [0.6, -0.4, 0.3, 0.9, -0.5, 0.7, 1.0]])
    duration = float(np.max(np.abs(qs[1] - qs[0]) / (VELOCITY * fraction)))
    return LinePlay(start, [0.0, duration], qs, *ramp_limits(LIMITS, fraction)), qs


def played(line: LinePlay, start: float, end: float) -> np.ndarray:
    return np.array([line.sample(t) for t in start + DT * np.arange(int((end - start) / DT) + 1)])


def test_ramp_limits_scale_like_the_speed_of_a_move() -> None:
    a1, j1 = ramp_limits(LIMITS, 1.0)
    a2, j2 = ramp_limits(LIMITS, 0.5)
    assert a1 == pytest.approx(float(np.min(ACCELERATION / VELOCITY)))
    assert j1 == pytest.approx(float(np.min(JERK / VELOCITY)))
    assert (a2, j2) == pytest.approx((a1 * 0.5, j1 * 0.25))


@pytest.mark.parametrize("fraction", [1.0, 0.3])
def test_a_line_starts_and_ends_at_rest_within_the_joint_limits(fraction: float) -> None:
    line, qs = one_segment(fraction)
    assert line.arrival > line.start + line.times[-1]  # the ramps take time
    q = played(line, line.start - 0.01, line.arrival + 0.01)
    velocity = np.diff(q, axis=0) / DT
    acceleration = np.diff(velocity, axis=0) / DT
    assert np.abs(velocity[:10]).max() < 1e-3 and np.abs(velocity[-10:]).max() < 1e-3
    assert (np.abs(velocity) <= VELOCITY * fraction * 1.001 + 1e-9).all()
    assert (np.abs(acceleration) <= ACCELERATION * fraction**2 * 1.01 + 1e-6).all()
    jerk = np.diff(acceleration, axis=0) / DT
    assert (np.abs(jerk) <= JERK * fraction**3 * 1.05 + 1e-3).all()
    # Every sample is on the segment, in order: the ramp changes timing, not the path.
    progress = (q - qs[0]) @ (qs[1] - qs[0]) / np.sum((qs[1] - qs[0]) ** 2)
    np.testing.assert_allclose(q, qs[0] + np.outer(progress, qs[1] - qs[0]), atol=1e-12)
    assert (np.diff(progress) >= -1e-12).all()
    assert progress[0] == 0.0 and progress[-1] == pytest.approx(1.0, abs=1e-12)


def test_a_brake_slows_down_on_the_path_and_stops_short_of_the_goal() -> None:
    line, qs = one_segment(1.0)
    planned = line.arrival
    t_brake = line.start + 0.3 * (planned - line.start)  # still speeding up
    grid = t_brake + DT * np.arange(-50, int((planned - t_brake) / DT) + 10)
    before = [line.sample(t) for t in grid[grid <= t_brake]]
    at_rest = line.brake(t_brake)
    assert t_brake < at_rest < planned
    q = np.array(before + [line.sample(t) for t in grid[grid > t_brake]])
    velocity = np.diff(q, axis=0) / DT
    acceleration = np.diff(velocity, axis=0) / DT
    assert (np.abs(acceleration) <= ACCELERATION * 1.01 + 1e-6).all()  # no jump at the brake
    assert np.abs(velocity[-10:]).max() < 1e-9  # at rest
    stop = np.array(line.sample(at_rest))
    progress = (stop - qs[0]) @ (qs[1] - qs[0]) / np.sum((qs[1] - qs[0]) ** 2)
    np.testing.assert_allclose(stop, qs[0] + progress * (qs[1] - qs[0]), atol=1e-12)
    assert line.path_time(t_brake)[0] / line.times[-1] < progress < 1.0


def test_waypoints_are_passed_in_order_at_their_path_times() -> None:
    qs = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    line = LinePlay(0.0, [0.0, 1.0, 3.0], qs, 2.0, 20.0)
    u = [line.path_time(t)[0] for t in np.arange(0.0, line.arrival + DT, DT)]
    assert (np.diff(u) >= 0).all() and u[-1] == pytest.approx(3.0)
    t_corner = next(t for t in np.arange(0.0, line.arrival, DT) if line.path_time(t)[0] >= 1.0)
    np.testing.assert_allclose(line.sample(t_corner), [1.0, 0.0], atol=2e-3)
    assert line.sample(line.arrival) == (1.0, 1.0)
