"""A planned path in time: each edge a rest-to-rest ruckig profile along the edge.

The planner's path is a polyline whose edges were checked, and nothing else
was. The arm must stay on it exactly, so each edge is played as one
joint-space line ``q = q_k + u * s`` (``u`` the edge's direction scaled to
``max |u_i| = 1``), with ``s`` a one-joint ruckig profile from 0 to the edge's
length, from rest to rest. Joint ``i`` then moves at ``u_i * ds/dt``, so
bounding ``ds/dt`` by ``min(v_i / |u_i|)`` (and the acceleration and jerk of
``s`` likewise) keeps every joint within its velocity, acceleration and jerk
limits, scaled by the speed fraction as ``motion.planner`` scales them (``f``,
``f**2``, ``f**3``).

Why rest at every corner: at a corner the direction changes at once, so a
joint velocity that stays continuous there must be zero; rounding the corner
instead (ruckig through waypoints, TOPP-RA over a spline) would leave the
checked polyline, and the rounded curve would need a check of its own. The
shortened paths have few corners (two or three on the benchmark's scenes), so
the stops cost little; ``brake`` stops on the edge being played.

Pure: times are the caller's clock [s]; nothing here reads one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory

from c2rviz.motion import MotionLimits

from .errors import BadPlanningSetting, PlanningError

State = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]


class TimingFailed(PlanningError):
    """ruckig could not time an edge (numbers beyond its numerical range)."""

    def __init__(self, edge: int, detail: str) -> None:
        self.edge = edge
        self.detail = detail
        super().__init__(f"cannot time the path's edge {edge}: {detail}")


@dataclass(frozen=True)
class _Edge:
    """One edge in time: from ``q0`` along ``u`` for ``length``, its profile from ``t0``,
    and from ``brake_at`` on (if it was braked), the brake's profile."""

    t0: float
    q0: np.ndarray
    u: np.ndarray
    length: float
    profile: Trajectory
    brake_at: float = math.inf
    brake: Trajectory | None = None

    @property
    def end(self) -> float:
        if self.brake is not None:
            return self.brake_at + self.brake.duration
        return self.t0 + self.profile.duration

    def at(self, t: float) -> tuple[float, float, float]:
        """``s`` [rad or m], its rate and its acceleration at the caller's ``t`` [s]."""
        profile, t0 = self.profile, self.t0
        if self.brake is not None and t >= self.brake_at:
            profile, t0 = self.brake, self.brake_at
        (s,), (rate,), (acceleration,) = profile.at_time(min(max(t - t0, 0.0), profile.duration))
        return min(max(s, 0.0), self.length), rate, acceleration


def _limits_along(u: np.ndarray, per_joint: Sequence[float]) -> float:
    """The most ``s`` may get when joint ``i`` gets ``u_i`` times it: min of limit / |u_i|."""
    moving = np.abs(u) > 0
    return float(np.min(np.asarray(per_joint)[moving] / np.abs(u[moving])))


def _profile(
    s: float, rate: float, acceleration: float, length: float, bounds: tuple[float, ...]
) -> tuple[Trajectory, Result]:
    """``s`` from (s, rate, acceleration) to rest: at ``length`` (position interface), or as
    soon as it can (velocity interface, when ``length`` is NaN)."""
    params = InputParameter(1)
    braking = math.isnan(length)
    params.control_interface = ControlInterface.Velocity if braking else ControlInterface.Position
    params.current_position = [s]
    params.current_velocity = [rate]
    params.current_acceleration = [acceleration]
    params.target_position = [s if braking else length]
    params.target_velocity = [0.0]
    params.target_acceleration = [0.0]
    params.max_velocity, params.max_acceleration, params.max_jerk = ([x] for x in bounds)
    profile = Trajectory(1)
    return profile, Ruckig(1).calculate(params, profile)


class TimedPath:
    """Waypoints played edge by edge, each from rest to rest, exactly on the polyline.

    Attributes:
        start: When the arm leaves the first waypoint, on the caller's clock [s].
        qs: The waypoints [rad or m], one row each.
        speed: The speed fraction it was timed at.
    """

    def __init__(
        self, waypoints: np.ndarray, limits: MotionLimits, start: float, speed: float = 1.0
    ) -> None:
        """Time ``waypoints`` from rest at ``start`` [s] within ``limits`` at ``speed``.

        Raises:
            BadPlanningSetting: waypoints of the wrong shape, not finite or
                outside the position limits, or a speed outside (0, 1].
            TimingFailed: ruckig refused an edge (not expected within the limits).
        """
        qs = np.array(waypoints, dtype=float, ndmin=2)
        n = limits.n
        if qs.ndim != 2 or qs.shape[1] != n or len(qs) == 0:
            raise BadPlanningSetting("waypoints", qs.shape, f"give rows of {n} values")
        low, high = np.array(limits.lower), np.array(limits.upper)
        if not np.all(np.isfinite(qs) & (qs >= low) & (qs <= high)):
            raise BadPlanningSetting("waypoints", "", "give finite values within the limits")
        if not (isinstance(speed, (int, float)) and 0 < speed <= 1):
            raise BadPlanningSetting("speed", speed, "give a fraction in (0, 1]")
        self.start = float(start)
        self.qs = qs
        self.speed = float(speed)
        self._limits = limits
        self._edges: list[_Edge] = []
        self._rest = qs[0].copy()  # where the arm is at rest before start and after the end
        t = self.start
        for k in range(len(qs) - 1):
            delta = qs[k + 1] - qs[k]
            length = float(np.max(np.abs(delta)))
            if length == 0:
                continue
            u = delta / length
            bounds = self._bounds(u)
            profile, result = _profile(0.0, 0.0, 0.0, length, bounds)
            if result not in (Result.Working, Result.Finished):
                raise TimingFailed(k, result.name)
            self._edges.append(_Edge(t, qs[k].copy(), u, length, profile))
            t += profile.duration
        self._end = t
        self._goal = qs[-1].copy()
        self._starts = np.array([edge.t0 for edge in self._edges])

    @property
    def joint_path(self) -> np.ndarray:
        """The polyline played: the waypoints [rad or m], one row each (the page draws
        the tool's line through them)."""
        return self.qs

    def _bounds(self, u: np.ndarray, f: float | None = None) -> tuple[float, float, float]:
        """Bounds of ``s`` along ``u`` at speed fraction ``f`` (the path's if None)."""
        f = self.speed if f is None else f
        limits = self._limits
        return (
            _limits_along(u, limits.velocity) * f,
            _limits_along(u, limits.acceleration) * f**2,
            _limits_along(u, limits.jerk) * f**3,
        )

    @property
    def arrival(self) -> float:
        """When the arm comes to rest: at the goal, or where a brake stops it [s]."""
        return self._end

    @property
    def duration(self) -> float:
        """How long the motion takes from ``start`` to ``arrival`` [s]."""
        return self._end - self.start

    def reach_times(self) -> list[float]:
        """When each edge's end is reached [s], on the caller's clock."""
        return [edge.end for edge in self._edges]

    def moving(self, t: float) -> bool:
        """True between ``start`` and ``arrival`` [s]."""
        return self.start <= t < self._end

    def state(self, t: float) -> State:
        """Position [rad or m], velocity [/s] and acceleration [/s^2] at the caller's ``t`` [s]."""
        zeros = (0.0,) * len(self._rest)
        if not self._edges or t < self.start:
            return tuple(self._rest.tolist()), zeros, zeros
        if t >= self._end:
            return tuple(self._goal.tolist()), zeros, zeros
        edge = self._edges[self._index(t)]
        s, rate, acceleration = edge.at(t)
        q = edge.q0 + edge.u * s
        return (
            tuple(q.tolist()),
            tuple((edge.u * rate).tolist()),
            tuple((edge.u * acceleration).tolist()),
        )

    def sample(self, t: float) -> tuple[float, ...]:
        """The chain values [rad or m] at the caller's time ``t`` [s]."""
        return self.state(t)[0]

    def brake(self, t: float) -> float:
        """From ``t`` [s] on, slow down on the edge being played to rest; return when.

        The stop is as quick as the joints' full limits allow along the edge (not
        the path's speed fraction's), and never passes the edge's end (a stop at
        limits at least those of a rest-to-rest profile is at least as short as
        the rest of it); at rest already, nothing changes.
        """
        if t >= self._end or not self._edges:
            return self._end
        t = max(t, self.start)
        k = self._index(t)
        edge = self._edges[k]
        s, rate, acceleration = edge.at(t)
        profile, result = _profile(s, rate, acceleration, math.nan, self._bounds(edge.u, 1.0))
        if result not in (Result.Working, Result.Finished):
            raise TimingFailed(k, f"braking ({result.name})")
        braked = _Edge(edge.t0, edge.q0, edge.u, edge.length, edge.profile, t, profile)
        self._edges = [*self._edges[:k], braked]  # what was played stays as it was
        self._end = braked.end
        self._goal = edge.q0 + edge.u * braked.at(self._end)[0]
        return self._end

    def _index(self, t: float) -> int:
        """The edge being played at ``t`` [s] (the first before ``start``, the last after)."""
        return max(0, int(np.searchsorted(self._starts, t, side="right")) - 1)


def time_path(
    waypoints: np.ndarray, limits: MotionLimits, start: float, speed: float = 1.0
) -> TimedPath:
    """``TimedPath(waypoints, limits, start, speed)``: the planned path in time (see the module)."""
    return TimedPath(waypoints, limits, start, speed)
