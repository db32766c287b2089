"""Joint paths played on the caller's clock: what a move along a path must offer the world,
the straight tool line's play and the planned trajectory's.

A straight tool line (``LinePlay``), a planned path around obstacles
(``planning.timing.TimedPath``) and a timed trajectory from a door are each a
``PathPlay``: sampled at the clock's time, ending at rest at a known time, and
able to brake to rest *on* its path (never leaving the path it was checked along).

``TrajectoryPlay`` is the ``PathPlay`` of one planned trajectory
(``trajectory.PlannedTrajectory``) from a start time: the chain at clock time ``t`` is
the trajectory at path time ``t - start``. A stop brakes *on* the path: path time slows
linearly to rest over as long as the fastest joint of the path needs to stop at its
acceleration limit, so the arm never leaves the path it was checked along.

``LinePlay`` is a straight tool line played in time: its joint path, eased in and out,
braked on the path. ``cartesian.StraightLine.timestamps`` times a line's waypoints for constant
speeds: the tool at ``lspeed`` at most, each joint at its velocity limit at
most. Played as is, the arm would start and stop at full speed. Here that
timing becomes *path time* ``u`` (seconds of the timed path), and a one-joint
ruckig profile ``u(t)`` carries the arm along it: ``u`` goes from 0 to the
path's duration with ``du/dt <= 1`` (never faster than the timing allows), and
its acceleration and jerk bounded so that every joint, whose path velocity
``dq/du`` is at most its velocity limit ``v``, gets at most its acceleration
limit ``a`` (and jerk limit ``j``) from the ramp: ``du^2/dt^2 <= min(a / v)``,
``du^3/dt^3 <= min(j / v)``, scaled by the speed fraction like ``motion``'s.
Between waypoints the joints still move linearly in ``u`` (their velocity
changes at a waypoint, as the line's direction in joint space does).

A stop brakes ``u`` to rest at the joints' full limits (``brake_limits``: a
line timed at speed fraction ``f`` has ``|dq/du| <= f * v``, so ``u`` may
decelerate at ``min(a / v) / f`` and jerk at ``min(j / v) / f**2``): the arm
slows down on the line and stops on it, short of the goal. Pure: times are the
caller's.

``line_brake``, the brake along a straight joint-space move (``motion.Motion``'s stop):
every joint stops at one common fraction. A move from rest to rest, phase-synchronized,
is the segment ``q = start + u * s`` (``max |u_i| = 1``). ``line_brake`` takes the state
of such a move (position, velocity and acceleration, all along ``u``), reads ``s`` and
its rates off the joint that moves most, and brakes ``s`` with a one-joint ruckig
profile (the velocity interface) whose limits are the tightest of the joints' along
``u``: ``min v_i / |u_i|``, ``min a_i / |u_i|``, ``min j_i / |u_i|``. So every joint is
within its full limits and the arm stays on the segment.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from ruckig import ControlInterface, InputParameter, Result, Ruckig, RuckigError, Trajectory

from .limits import MotionLimits, MotionPlanError
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


def ramp_limits(limits: MotionLimits, fraction: float) -> tuple[float, float]:
    """The path-time acceleration and jerk [1/s, 1/s^2] a line gets at speed ``fraction``."""
    velocity = np.asarray(limits.velocity)
    acceleration = float(np.min(np.asarray(limits.acceleration) / velocity))
    jerk = float(np.min(np.asarray(limits.jerk) / velocity))
    return acceleration * fraction, jerk * fraction**2


def brake_limits(limits: MotionLimits, fraction: float) -> tuple[float, float]:
    """The path-time acceleration and jerk [1/s, 1/s^2] a line timed at speed ``fraction``
    may brake with: the joints' full acceleration and jerk (see the module)."""
    acceleration, jerk = ramp_limits(limits, 1.0)
    return acceleration / fraction, jerk / fraction**2


class LinePlay:
    """A joint path played along its own timing, eased by a path-time profile.

    Attributes:
        start: When the arm leaves the first waypoint, on the caller's clock [s].
        times: Path time of each waypoint [s], increasing from 0.
        qs: The waypoints' chain values [rad or m], one row each.
    """

    def __init__(
        self,
        start: float,
        times: Sequence[float],
        qs: np.ndarray,
        acceleration: float,
        jerk: float,
        brake: tuple[float, float] | None = None,
    ) -> None:
        """Ease in at ``start`` and out at the last waypoint.

        Args:
            start: The caller's time now [s].
            times: Path time of each waypoint [s], from 0, increasing.
            qs: The waypoints [rad or m], one row each.
            acceleration: Most path-time acceleration [1/s] (``ramp_limits``).
            jerk: Most path-time jerk [1/s^2] (``ramp_limits``).
            brake: Path-time acceleration and jerk a stop may use (``brake_limits``;
                the ramp's when None).
        """
        self.start = start
        self.times = np.asarray(times, dtype=float)
        self.qs = np.asarray(qs, dtype=float)
        self._limits = (acceleration, jerk)
        self._brake_limits = brake if brake is not None else self._limits
        self._origin = start  # the profile's time 0 on the caller's clock
        self._profile = self._plan(0.0, 0.0, 0.0, ControlInterface.Position)

    @property
    def joint_path(self) -> np.ndarray:
        """The waypoints played [rad or m], one row each (the page draws the tool's line)."""
        return self.qs

    @property
    def arrival(self) -> float:
        """When the arm comes to rest: at the goal, or where a brake stops it [s]."""
        return self._origin + self._profile.duration

    def path_time(self, t: float) -> tuple[float, float, float]:
        """Path time ``u`` [s], its rate and its acceleration at the caller's time ``t``."""
        u, rate, acceleration = self._profile.at_time(max(t - self._origin, 0.0))
        return min(max(u[0], 0.0), float(self.times[-1])), rate[0], acceleration[0]

    def sample(self, t: float) -> tuple[float, ...]:
        """The chain values at the caller's time ``t``."""
        u = self.path_time(t)[0]
        k = int(np.searchsorted(self.times, u, side="right"))
        if k >= len(self.times):
            return tuple(self.qs[-1].tolist())
        if k == 0:
            return tuple(self.qs[0].tolist())
        u0, u1 = self.times[k - 1], self.times[k]
        f = (u - u0) / (u1 - u0) if u1 > u0 else 1.0
        return tuple((self.qs[k - 1] + f * (self.qs[k] - self.qs[k - 1])).tolist())

    def state(self, t: float) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        """Position [rad or m], velocity [/s] and acceleration [/s^2] at the caller's ``t``
        (the joints move linearly in ``u`` between waypoints)."""
        u, rate, acceleration = self.path_time(t)
        k = min(max(int(np.searchsorted(self.times, u, side="right")), 1), len(self.times) - 1)
        span = self.times[k] - self.times[k - 1]
        slope = (self.qs[k] - self.qs[k - 1]) / span if span > 0 else np.zeros(self.qs.shape[1])
        if u >= self.times[-1]:
            slope = np.zeros(self.qs.shape[1])
        return (
            self.sample(t),
            tuple((slope * rate).tolist()),
            tuple((slope * acceleration).tolist()),
        )

    def brake(self, t: float) -> float:
        """From ``t`` on, slow down on the path to rest; return when the arm is at rest."""
        u, rate, acceleration = self.path_time(t)
        self._profile = self._plan(
            u, rate, acceleration, ControlInterface.Velocity, self._brake_limits
        )
        self._origin = t
        return self.arrival

    def _plan(
        self,
        u: float,
        rate: float,
        acceleration: float,
        interface: ControlInterface,
        limits: tuple[float, float] | None = None,
    ) -> Trajectory:
        max_acceleration, max_jerk = self._limits if limits is None else limits
        params = InputParameter(1)
        params.control_interface = interface
        params.current_position = [u]
        params.current_velocity = [rate]
        params.current_acceleration = [acceleration]
        params.target_position = [float(self.times[-1])]
        params.target_velocity = [0.0]
        params.target_acceleration = [0.0]
        params.max_velocity = [1.0]
        params.max_acceleration = [max_acceleration]
        params.max_jerk = [max_jerk]
        profile = Trajectory(1)
        result = Ruckig(1).calculate(params, profile)
        if result not in (Result.Working, Result.Finished):
            raise MotionPlanError(f"the line's ramp ({result.name})")
        return profile


State = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]
LINE_TOLERANCE = 1e-6  # relative: (q, v, a) this close to the segment lie on it


class LineBrake:
    """A brake along a straight move: ``q = start + u * s(t)``, ``s`` one ruckig profile.

    Plays as a ruckig ``Trajectory`` of all joints does (``at_time``, ``duration``).
    """

    def __init__(
        self, start: np.ndarray, u: np.ndarray, length: float, profile: Trajectory
    ) -> None:
        self.start = start
        self.u = u
        self.profile = profile
        self.duration = profile.duration
        s_end = profile.at_time(profile.duration)[0][0]
        self.beyond = s_end >= length  # it would pass the segment's end
        self.rest = tuple((start + u * min(s_end, length)).tolist())

    def at_time(self, t: float) -> tuple[list[float], list[float], list[float]]:
        (s,), (rate,), (acceleration,) = self.profile.at_time(min(t, self.duration))
        return (
            (self.start + self.u * s).tolist(),
            (self.u * rate).tolist(),
            (self.u * acceleration).tolist(),
        )


def line_brake(
    line: tuple[np.ndarray, np.ndarray], state: State, limits: MotionLimits
) -> LineBrake | None:
    """A brake of ``s`` along ``line`` (start, goal) from ``state`` at the full ``limits``,
    or None when the state is off the line."""
    start, goal = line
    delta = goal - start
    length = float(np.max(np.abs(delta)))
    if length == 0:
        return None
    u = delta / length
    k = int(np.argmax(np.abs(u)))
    q, v, a = (np.asarray(x, dtype=float) for x in state)
    s, rate, acceleration = (q[k] - start[k]) / u[k], v[k] / u[k], a[k] / u[k]
    for x, along in ((q - start, s), (v, rate), (a, acceleration)):
        scale = max(1.0, float(np.max(np.abs(x))))
        if float(np.max(np.abs(x - u * along))) > LINE_TOLERANCE * scale:
            return None
    moving = np.abs(u) > 0
    bounds = [
        float(np.min(np.asarray(per_joint)[moving] / np.abs(u[moving])))
        for per_joint in (limits.velocity, limits.acceleration, limits.jerk)
    ]
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position, inp.current_velocity = [s], [rate]
    inp.current_acceleration = [min(max(acceleration, -bounds[1]), bounds[1])]
    inp.target_velocity = inp.target_acceleration = [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = ([b] for b in bounds)
    profile = Trajectory(1)
    try:
        Ruckig(1).calculate(inp, profile)
    except RuckigError:
        return None
    return LineBrake(start, u, length, profile)
