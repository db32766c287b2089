"""A joint path played on the caller's clock: what a move along a path must offer the world.

A straight tool line (``line_play.LinePlay``), a planned path around obstacles
(``planning.timing.TimedPath``) and a timed trajectory from a door are each a
``PathPlay``: sampled at the clock's time, ending at rest at a known time, and
able to brake to rest *on* its path (never leaving the path it was checked along).

``TrajectoryPlay`` is the ``PathPlay`` of one planned trajectory
(``trajectory.PlannedTrajectory``) from a start time: the chain at clock time ``t`` is
the trajectory at path time ``t - start``. A stop brakes *on* the path: path time slows
linearly to rest over as long as the fastest joint of the path needs to stop at its
acceleration limit, so the arm never leaves the path it was checked along. Pure: the
caller's clock.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .trajectory import PlannedTrajectory


class PathPlay(Protocol):
    """A joint path with its timing, on the caller's clock [s]."""

    @property
    def arrival(self) -> float:
        """When the path comes to rest [s]."""
        ...

    def sample(self, t: float) -> tuple[float, ...]:
        """The chain's values at time ``t`` [s] (at rest at the end after ``arrival``)."""
        ...

    def brake(self, t: float) -> float:
        """From time ``t`` [s] slow down to rest on the path as fast as the limits allow;
        return the new arrival [s]."""
        ...


class TrajectoryPlay:
    """A planned trajectory played from ``start`` on the caller's clock (a ``PathPlay``)."""

    def __init__(self, planned: PlannedTrajectory, start: float) -> None:
        """Play ``planned`` from clock time ``start`` [s]."""
        self.planned = planned
        self.start = start
        self._brake: tuple[float, float, float] | None = None  # (clock t, path s, ramp [s])
        self._arrival = start + planned.duration

    @property
    def arrival(self) -> float:
        """When the arm comes to rest: at the last point, or where a brake stops it [s]."""
        return self._arrival

    def path_time(self, t: float) -> float:
        """Path time [s] at clock time ``t`` [s]: ``t - start``, or slowing on a brake."""
        if self._brake is None:
            return t - self.start
        t0, s0, ramp = self._brake
        dt = min(max(t - t0, 0.0), ramp)
        return s0 + dt - dt * dt / (2 * ramp)

    def sample(self, t: float) -> tuple[float, ...]:
        """The chain values [rad or m] at clock time ``t`` (at rest after ``arrival``)."""
        return tuple(self.planned.sample(self.path_time(t)).tolist())

    def brake(self, t: float) -> float:
        """From ``t`` slow down on the path to rest; return when the arm is at rest [s].

        Path time's rate falls from 1 to 0 linearly over the time the fastest joint
        of the path needs to stop at its acceleration limit (its peak speed over it).
        """
        if self._brake is not None or t >= self._arrival:
            return self._arrival
        planned = self.planned
        acceleration = np.asarray(planned.limits.acceleration)
        ramp = max(float(np.max(planned.peak_rate / acceleration)), 1e-3)
        s = self.path_time(t)
        if s + ramp / 2 >= planned.duration:
            return self._arrival  # the path comes to rest sooner by itself
        self._brake = (t, s, ramp)
        self._arrival = t + ramp
        return self._arrival
