"""Motion that takes time: jerk-limited, time-synchronized moves of one chain (ruckig).

A ``Motion`` holds the planned trajectory of one robot's chain and is *sampled*
at the caller's time ``t`` [s]: nothing here reads a clock, sleeps or steps a
queue. Each command plans one ruckig trajectory from the arm's state at that
instant (position, velocity AND acceleration), so a new target preempts a move
without a jump and without stopping first.

Speed. A fraction ``f`` in (0, 1] scales the limits as a slower clock would:
velocity by ``f``, acceleration by ``f**2``, jerk by ``f**3``. A move from rest
at speed ``f`` is then exactly the full-speed move played ``1/f`` times slower:
same path, duration divided by ``f``, rather than a crawl that still jerks at
full acceleration. A plan that starts while the arm moves scales acceleration
and jerk by ``max(f, r)`` instead, where ``r`` is the smallest fraction whose
limits hold the arm's present velocity and acceleration: slowing a fast arm
down never gets a slow arm's acceleration (at 10 % that is 1 % of it, a brake
50 times longer). If that plan would leave the position limits, the fraction
of the plan it replaces is used, which could stop in time.

Position limits. ruckig's community edition ignores ``min_position`` and
``max_position`` (a Pro feature), so the planner keeps within the joint limits
itself. From rest it asks for *phase* synchronization: every joint follows one
profile scaled, so the path is the straight segment between two in-limit
configurations, inside the limit box because a box is convex. A plan from a
moving state could overshoot, so each plan's per-joint position range is
computed exactly from its jerk profiles (``_position_range``; ruckig 0.19's own
``Trajectory.position_extrema`` misses extrema inside sections when the start
moves). A plan that leaves the limits is replaced by a brake to rest and a move
from there; only if even the brake left them (a state this planner made cannot
need that) are sampled positions clamped.

Continuous joints have the robot's finite limits (``robot.CONTINUOUS_LIMIT``,
kept like any other) and go to the literal value given (no wrapping: the caller
chooses the turn). Prismatic joints are in [m].
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np
from ruckig import (
    ControlInterface,
    InputParameter,
    Profile,
    Ruckig,
    RuckigError,
    Synchronization,
    Trajectory,
)

from .errors import C2rvizError, JointCountError
from .motion_limits import MotionLimitError, MotionLimits, motion_limits

__all__ = ["Motion", "MotionLimitError", "MotionLimits", "MotionPlanError", "motion_limits"]

State = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]
Plan = tuple[tuple[float, Trajectory], ...]  # (start time [s], trajectory) in order

# ruckig's synchronization step can fail for a start exactly on an acceleration
# limit, as every replan in a saturated phase is; 1e-12 inside it succeeds.
_NUDGE = 1 - 1e-12
_POSITION_TOLERANCE = 1e-9  # [rad or m] slack on the position limits for rounding


class MotionPlanError(C2rvizError):
    """ruckig could not plan the motion (numbers beyond its numerical range)."""

    def __init__(self, detail: str) -> None:
        self.detail = detail
        super().__init__(f"cannot plan the motion: {detail}")


def _sections(profile: Profile) -> Iterator[tuple[float, float, float, float, float]]:
    """(duration, p, v, a, jerk) of each constant-jerk section, as ``at_time`` plays them."""
    brake = profile.brake
    if brake.duration > 0:  # the brake pre-trajectory runs first
        yield from zip(brake.t, brake.p, brake.v, brake.a, brake.j)
    yield from zip(profile.t, profile.p, profile.v, profile.a, profile.j)


def _position_range(profile: Profile) -> tuple[float, float]:
    """Lowest and highest position [rad or m] of one joint's profile, exactly.

    Each section is a cubic in time; its extrema lie at its ends or where the
    velocity ``v + a*tau + j*tau**2/2`` is zero inside it. After its last
    section a profile holds its final state (at rest in every plan made here).
    """
    low = high = profile.p[-1]
    for duration, p, v, a, j in _sections(profile):
        if duration <= 0:  # unused sections may hold stale numbers
            continue
        low, high = min(low, p), max(high, p)
        if j != 0:
            discriminant = a * a - 2 * j * v
            if discriminant < 0:
                continue
            root = math.sqrt(discriminant)
            roots: tuple[float, ...] = ((-a + root) / j, (-a - root) / j)
        elif a != 0:
            roots = (-v / a,)
        else:
            continue
        for tau in roots:
            if 0 < tau < duration:
                x = p + tau * (v + tau * (a / 2 + tau * j / 6))
                low, high = min(low, x), max(high, x)
    return low, high


class Motion:
    """The planned motion of one chain, sampled at the caller's time ``t`` [s].

    Times are absolute on the caller's clock (any origin) and must not go
    backwards between calls. Use from one thread.
    """

    def __init__(self, limits: MotionLimits, q: Sequence[float]) -> None:
        """Start at rest at ``q`` [rad or m], which must be within the limits."""
        self.limits = limits
        self._n = n = limits.n
        self._otg = Ruckig(n)
        self._inp = InputParameter(n)
        self._velocity = np.array(limits.velocity)
        self._acceleration = np.array(limits.acceleration)
        self._jerk = np.array(limits.jerk)
        self._lower = np.array(limits.lower)
        self._upper = np.array(limits.upper)
        self._bounded = [
            i for i in range(n) if math.isfinite(limits.lower[i]) or math.isfinite(limits.upper[i])
        ]
        self._zeros = (0.0,) * n
        self._plan: Plan = ()
        self._end = -math.inf  # [s] when the plan comes to rest
        self._target = self._check_target(q)
        self._speed = 1.0  # velocity fraction of the plan
        self._scale = 1.0  # acceleration (squared) and jerk (cubed) fraction of the plan
        self._clamp = False

    # --- state ------------------------------------------------------------------

    def sample(self, t: float) -> State:
        """Position [rad or m], velocity [/s] and acceleration [/s^2] at time ``t`` [s].

        After the plan's end: at rest at the target. One ruckig ``at_time``.
        """
        if t >= self._end or not self._plan:
            return self._target, self._zeros, self._zeros
        start, trajectory = self._plan[0]
        if len(self._plan) > 1 and t >= self._plan[1][0]:
            start, trajectory = self._plan[1]
        p, v, a = trajectory.at_time(max(t - start, 0.0))
        if self._clamp:
            p = np.clip(p, self._lower, self._upper).tolist()
        return tuple(p), tuple(v), tuple(a)

    def moving(self, t: float) -> bool:
        """True while the plan has not come to rest at time ``t`` [s]."""
        return t < self._end

    def arrival(self) -> float:
        """Time [s] the plan comes (or came) to rest; ``-inf`` if it never moved."""
        return self._end

    @property
    def target(self) -> tuple[float, ...]:
        """Where the plan comes to rest [rad or m]."""
        return self._target

    # --- commands ---------------------------------------------------------------

    def jump(self, q: Sequence[float], t: float) -> None:
        """Be at rest at ``q`` [rad or m] from time ``t`` [s] on (motion off, teleport)."""
        target = self._check_target(q)
        self._set((), target, 1.0, 1.0, clamp=False)
        self._end = t

    def move_to(self, target: Sequence[float], t: float, speed: float = 1.0) -> float:
        """Plan from the state at ``t`` [s] to rest at ``target``; return arrival [s].

        All joints start and arrive together. ``speed`` in (0, 1] scales
        velocity by ``speed``, acceleration by ``speed**2``, jerk by ``speed**3``.

        Raises:
            JointCountError: ``target`` has the wrong number of values.
            MotionLimitError: a target outside the limits, or a bad speed.
            MotionPlanError: ruckig failed (not expected within the limits).
        """
        goal = self._check_target(target)
        speed = self._check_speed(speed)
        q, v, a = self.sample(t)
        scale = max(speed, self._scale) if t < self._end else speed
        trajectory = self._position(q, v, a, goal, speed, scale)
        excess = self._excess(trajectory)
        if excess <= _POSITION_TOLERANCE:
            self._set(((t, trajectory),), goal, speed, scale, clamp=excess > 0)
            return self._end
        brake, excess, scale = self._brake(q, v, a, scale)
        rest = np.clip(brake.at_time(brake.duration)[0], self._lower, self._upper).tolist()
        move = self._position(rest, self._zeros, self._zeros, goal, speed, speed)
        clamp = max(excess, self._excess(move)) > 0
        self._set(((t, brake), (t + brake.duration, move)), goal, speed, scale, clamp)
        return self._end

    def follow(self, target: Sequence[float], t: float, speed: float = 1.0) -> None:
        """A streamed setpoint: like ``move_to``, and nothing if it is the present one.

        The arm follows within the limits, lags a target that moves faster than
        it can, and comes to rest at the last setpoint.
        """
        if tuple(target) != self._target or speed != self._speed:
            self.move_to(target, t, speed)

    def stop(self, t: float) -> float:
        """Decelerate to rest within the limits from time ``t`` [s]; return rest time [s].

        The brake stays on the path where ruckig can phase-synchronize it.
        """
        if t >= self._end:
            return self._end
        q, v, a = self.sample(t)
        brake, excess, scale = self._brake(q, v, a, self._scale)
        rest = np.clip(brake.at_time(brake.duration)[0], self._lower, self._upper)
        self._set(((t, brake),), tuple(rest.tolist()), self._speed, scale, excess > 0)
        return self._end

    # --- planning ---------------------------------------------------------------

    def _set(
        self, plan: Plan, goal: tuple[float, ...], speed: float, scale: float, clamp: bool
    ) -> None:
        self._plan = plan
        if plan:
            start, last = plan[-1]
            self._end = start + last.duration
        self._target = goal
        self._speed = speed
        self._scale = scale
        self._clamp = clamp

    def _calculate(self, speed: float, scale: float) -> Trajectory:
        inp = self._inp
        inp.max_velocity = (self._velocity * speed).tolist()
        inp.max_acceleration = (self._acceleration * scale**2).tolist()
        inp.max_jerk = (self._jerk * scale**3).tolist()
        trajectory = Trajectory(self._n)
        try:
            self._otg.calculate(inp, trajectory)
        except RuckigError:
            inp.current_acceleration = [x * _NUDGE for x in inp.current_acceleration]
            try:
                self._otg.calculate(inp, trajectory)
            except RuckigError as exc:
                lines = str(exc).strip().splitlines()
                raise MotionPlanError(lines[0] if lines else "ruckig failed") from exc
        return trajectory

    def _position(
        self,
        q: Sequence[float],
        v: Sequence[float],
        a: Sequence[float],
        goal: Sequence[float],
        speed: float,
        scale: float,
    ) -> Trajectory:
        """A trajectory from (q, v, a) to rest at ``goal``, phase-synchronized if it can be."""
        inp = self._inp
        inp.control_interface = ControlInterface.Position
        inp.synchronization = Synchronization.Phase  # ruckig falls back to Time
        inp.current_position, inp.current_velocity, inp.current_acceleration = q, v, a
        inp.target_position = goal
        inp.target_velocity = inp.target_acceleration = self._zeros
        return self._calculate(speed, scale)

    def _brake(
        self, q: Sequence[float], v: Sequence[float], a: Sequence[float], scale: float
    ) -> tuple[Trajectory, float, float]:
        """A trajectory from (q, v, a) to rest, how far [rad or m] it leaves the limits
        and the acceleration/jerk fraction it took.

        Phase-synchronized (on the path) if ruckig can and that keeps within the
        limits, else every joint brakes on its own as fast as it may. Coming to
        rest takes a jerk ramp that a plan turning round does not, so a brake at
        the plan's own ``scale`` can end past a limit the plan stayed within;
        then it brakes harder, up to the full limits.
        """
        inp = self._inp
        inp.control_interface = ControlInterface.Velocity
        inp.current_position, inp.current_velocity, inp.current_acceleration = q, v, a
        inp.target_velocity = inp.target_acceleration = self._zeros
        inp.synchronization = Synchronization.No
        for harder in (scale, 1.0) if scale < 1 else (scale,):
            brake = self._calculate(harder, harder)
            excess = self._excess(brake)
            if excess <= _POSITION_TOLERANCE:
                break
        return brake, excess, harder

    def _excess(self, trajectory: Trajectory) -> float:
        """How far [rad or m] the trajectory goes beyond any position limit (0: within)."""
        profiles = trajectory.profiles[0]
        excess = 0.0
        for i in self._bounded:
            low, high = _position_range(profiles[i])
            excess = max(excess, self._lower[i] - low, high - self._upper[i])
        return excess

    def _check_speed(self, speed: float) -> float:
        if not (math.isfinite(speed) and 0 < speed <= 1):
            raise MotionLimitError("speed", f"{speed} must be a fraction in (0, 1]")
        return float(speed)

    def _check_target(self, q: Sequence[float]) -> tuple[float, ...]:
        values = tuple(float(x) for x in q)
        if len(values) != self._n:
            raise JointCountError(self._n, len(values))
        for i, (x, low, high) in enumerate(zip(values, self.limits.lower, self.limits.upper)):
            if not (math.isfinite(x) and low <= x <= high):
                raise MotionLimitError(
                    "target", f"joint {i} = {x} is not a finite value within {low}..{high}"
                )
        return values
