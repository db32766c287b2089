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
full acceleration. A plan that starts while the arm moves takes the new
velocity fraction at once (ruckig brakes down to it) but keeps at least the
acceleration and jerk fraction of the plan it replaces: slowing a fast arm
never gets a slow arm's acceleration (at 10 % that is 1 % of it, a brake 50
times longer), and what the old plan could do from this state (stop before a
limit, ramp its acceleration down before passing its velocity limit) the new
plan can too. Once the arm is at rest the commanded fraction alone counts.

Stop. The arm brakes at the joints' full limits, whatever the move's speed (a
stop at 5 % speed would otherwise take 1/0.05**2 = 400 times the braking
acceleration's time). A move that started from rest is a straight segment in
joint space (phase synchronization, below): it brakes along that segment. Its
path parameter ``s`` (``q = start + u * s``, ``max |u_i| = 1``) is braked by a
one-joint ruckig profile whose limits are the tightest of the joints' along
``u`` (``min v_i / |u_i|`` and likewise), so every joint stops at one common
fraction of its travel and the arm stays on the path the guard checked
(ruckig's own phase-synchronized brake falls back to time synchronization,
off the line, when the limiting joint's profile scaled would break another
joint's limits). Any other plan (a preemption blended from a moving state)
brakes each joint on its own (no synchronization): a synchronized brake slows
the quicker joints' braking, and they coast past the target they were heading
for. The tests check that a stop ends between start and target.

Position limits. ruckig's community edition ignores ``min_position`` and
``max_position`` (a Pro feature), so the planner keeps within the joint limits
itself. From rest it asks for *phase* synchronization: every joint follows one
profile scaled, so the path is the straight segment between two in-limit
configurations, inside the limit box because a box is convex. From a moving
state there is no such argument: a time-synchronized joint that is not the
slowest may coast past a limit before it turns back. So every plan's exact
per-joint range is computed from its jerk profiles (``_position_range``;
ruckig 0.19's ``Trajectory.position_extrema`` misses extrema inside sections
when the start moves), and a preempting plan that passes a limit is replaced by
a brake to rest followed by a move from rest. What is left, of rounding size
(under 1e-8 in 60,000 random plans), is ``Motion.overshoot``, and sampled
positions are clamped to the limits whenever it is not 0.

Continuous joints have the robot's finite limits (``robot.CONTINUOUS_LIMIT``,
kept like any other) and go to the literal value given (no wrapping: the caller
chooses the turn). Prismatic joints are in [m].
"""

from __future__ import annotations

import math
from collections.abc import Sequence

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

from ..errors import JointCountError
from .limits import MotionLimitError, MotionLimits, MotionPlanError
from .path_play import LineBrake, line_brake

State = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]
Plan = tuple[tuple[float, "Trajectory | LineBrake"], ...]  # (start time [s], plan), in order

_TOLERANCE = 1e-6  # [rad or m] an overshoot up to this (rounding) is only clamped
_TIGHTER = (1.0, 1 - 1e-12, 1 - 1e-9)  # acceleration/jerk limit factors ruckig is retried with


def _position_range(profile: Profile) -> tuple[float, float]:
    """Lowest and highest position [rad or m] of one joint's ruckig profile, exactly.

    ruckig plays a profile as its brake sections (if any) and then seven
    constant-jerk sections, whose boundary states are ``p``, ``v``, ``a``; after
    the last it holds the final state. In each section the position is a cubic,
    so its extrema lie at the boundaries or where the velocity
    ``v + a*tau + j*tau**2/2`` is zero inside, which needs the velocity to
    change sign or the acceleration to (a velocity peak) across the section.
    """
    p, v, a = profile.p, profile.v, profile.a
    low, high = min(p), max(p)
    turning = [
        (duration, p[k], v[k], a[k], jerk)
        for k, (duration, jerk) in enumerate(zip(profile.t, profile.j))
        if v[k] * v[k + 1] < 0 or a[k] * a[k + 1] < 0
    ]
    brake = profile.brake
    if brake.duration > 0:  # unused brake sections hold stale numbers: skip them
        turning += [s for s in zip(brake.t, brake.p, brake.v, brake.a, brake.j) if s[0] > 0]
    for duration, p0, v0, a0, jerk in turning:
        low, high = min(low, p0), max(high, p0)
        if jerk != 0:
            discriminant = a0 * a0 - 2 * jerk * v0
            if discriminant < 0:
                continue
            root = math.sqrt(discriminant)
            roots: tuple[float, ...] = ((-a0 + root) / jerk, (-a0 - root) / jerk)
        elif a0 != 0:
            roots = (-v0 / a0,)
        else:
            continue
        for tau in roots:
            if 0 < tau < duration:
                x = p0 + tau * (v0 + tau * (a0 / 2 + tau * jerk / 6))
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
        self._bounded = [  # (index, lower, upper) of each joint with a finite limit
            (i, low, high)
            for i, (low, high) in enumerate(zip(limits.lower, limits.upper))
            if math.isfinite(low) or math.isfinite(high)
        ]
        self._zeros = (0.0,) * n
        self._plan: Plan = ()  # empty: at rest at the target
        self._end = -math.inf  # [s] when the plan comes to rest
        self._target = self._check_target(q)
        self._speed = 1.0  # velocity fraction of the plan
        self._scale = 1.0  # acceleration (squared) and jerk (cubed) fraction of the plan
        self._overshoot = 0.0
        self._line: tuple[np.ndarray, np.ndarray] | None = None  # a straight plan: (start, goal)

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
        if self._overshoot:
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

    @property
    def overshoot(self) -> float:
        """How far [rad or m] the plan passes a position limit before clamping (0: not)."""
        return self._overshoot

    # --- commands ---------------------------------------------------------------

    def jump(self, q: Sequence[float], t: float) -> None:
        """Be at rest at ``q`` [rad or m] from time ``t`` [s] on (motion off, teleport)."""
        self._target = self._check_target(q)
        self._plan = ()
        self._end = t
        self._speed = self._scale = 1.0
        self._overshoot = 0.0
        self._line = None

    def take_over(self, state: State, t: float) -> None:
        """The arm is at ``state`` (position [rad or m], velocity, acceleration) at ``t``
        [s], moving along a path played elsewhere: from here it brakes, each joint at
        its full limits, unless a move planned at ``t`` replaces that (then the move
        blends from this state, as a preemption does)."""
        q, v, a = (tuple(float(x) for x in values) for values in state)
        if not any(v) and not any(a):
            self.jump(q, t)
            return
        brake = self._brake(q, v, a, 1.0)
        rest = np.clip(brake.at_time(brake.duration)[0], self._lower, self._upper)
        self._set(((t, brake),), tuple(rest.tolist()), 1.0, 1.0)
        self._line = None

    def move_to(self, target: Sequence[float], t: float, speed: float = 1.0) -> float:
        """Plan from the state at ``t`` [s] to rest at ``target``; return arrival [s].

        All joints start and arrive together. ``speed`` in (0, 1] scales
        velocity by ``speed``, acceleration by ``speed**2``, jerk by ``speed**3``
        (while the arm moves, acceleration and jerk by at least the fraction of
        the plan being replaced).

        Raises:
            JointCountError: ``target`` has the wrong number of values.
            MotionLimitError: a target outside the limits, or a bad speed.
            MotionPlanError: ruckig failed (not expected within the limits).
        """
        goal = self._check_target(target)
        speed = self._check_speed(speed)
        q, v, a = self.sample(t)
        moving = t < self._end
        scale = max(speed, self._scale) if moving else speed
        trajectory = self._position(q, v, a, goal, speed, scale)
        plan: Plan = ((t, trajectory),)
        if self._overshoot_of(trajectory) > _TOLERANCE:
            brake = self._brake(q, v, a, scale)
            rest = np.clip(brake.at_time(brake.duration)[0], self._lower, self._upper).tolist()
            move = self._position(rest, self._zeros, self._zeros, goal, speed, speed)
            plan = ((t, brake), (t + brake.duration, move))
        self._set(plan, goal, speed, scale)
        self._line = None if moving else (np.array(q), np.array(goal))
        return self._end

    def follow(self, target: Sequence[float], t: float, speed: float = 1.0) -> None:
        """A streamed setpoint: like ``move_to``, and nothing if it is the present one.

        The arm follows within the limits, lags a target that moves faster than
        it can, and comes to rest at the last setpoint.
        """
        if tuple(target) != self._target or speed != self._speed:
            self.move_to(target, t, speed)

    def stop(self, t: float) -> float:
        """Decelerate to rest from time ``t`` [s] at the joints' full limits; return rest
        time [s].

        A move from rest brakes along its straight segment (every joint at one common
        fraction); any other plan brakes each joint on its own. At rest already:
        nothing changes and the time it came to rest is returned.
        """
        if t >= self._end:
            return self._end
        q, v, a = self.sample(t)
        if self._line is not None:
            brake = line_brake(self._line, (q, v, a), self.limits)
            if brake is not None:
                if brake.beyond:  # so near the end that braking would pass it: it stops first
                    return self._end
                self._set(((t, brake),), brake.rest, self._speed, 1.0)
                return self._end  # still on the segment: a stop again brakes along it
        joints = self._brake(q, v, a, 1.0)
        rest = np.clip(joints.at_time(joints.duration)[0], self._lower, self._upper)
        self._set(((t, joints),), tuple(rest.tolist()), self._speed, 1.0)
        self._line = None
        return self._end

    @property
    def straight(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The segment (start, goal) [rad or m] a move from rest travels along (and a stop
        of it brakes along), or None for a plan that is not one (a preemption from a
        moving state)."""
        return self._line

    # --- planning ---------------------------------------------------------------

    def _set(self, plan: Plan, goal: tuple[float, ...], speed: float, scale: float) -> None:
        start, last = plan[-1]
        self._plan = plan
        self._end = start + last.duration
        self._target = goal
        self._speed = speed
        self._scale = scale
        self._overshoot = max(self._overshoot_of(trajectory) for _, trajectory in plan)

    def _position(
        self,
        q: Sequence[float],
        v: Sequence[float],
        a: Sequence[float],
        goal: Sequence[float],
        speed: float,
        scale: float,
    ) -> Trajectory:
        """From (q, v, a) to rest at ``goal``, phase-synchronized where ruckig can."""
        inp = self._inp
        inp.control_interface = ControlInterface.Position
        inp.synchronization = Synchronization.Phase  # ruckig falls back to Time
        inp.current_position, inp.current_velocity, inp.current_acceleration = q, v, a
        inp.target_position = goal
        inp.target_velocity = inp.target_acceleration = self._zeros
        return self._calculate(speed, scale)

    def _brake(
        self, q: Sequence[float], v: Sequence[float], a: Sequence[float], scale: float
    ) -> Trajectory:
        """Every joint from (q, v, a) to rest on its own, as fast as ``scale`` allows."""
        inp = self._inp
        inp.control_interface = ControlInterface.Velocity
        inp.synchronization = Synchronization.No
        inp.current_position, inp.current_velocity, inp.current_acceleration = q, v, a
        inp.target_velocity = inp.target_acceleration = self._zeros
        return self._calculate(scale, scale)

    def _overshoot_of(self, trajectory: Trajectory | LineBrake) -> float:
        """How far [rad or m] ``trajectory`` passes a position limit (0: within)."""
        if isinstance(trajectory, LineBrake):
            return 0.0  # on a segment between two points within the limits
        profiles = trajectory.profiles[0]
        overshoot = 0.0
        for i, lower, upper in self._bounded:
            low, high = _position_range(profiles[i])
            overshoot = max(overshoot, lower - low, high - upper)
        return overshoot

    def _calculate(self, speed: float, scale: float) -> Trajectory:
        """ruckig on ``self._inp`` with the limits at fractions ``speed`` and ``scale``.

        ruckig 0.19 fails on rare degenerate inputs (about 1 in 30,000 moves
        between rounded values at a rounded speed; tests/test_motion.py keeps
        two): then acceleration and jerk limits a hair tighter, and at last
        each joint on its own (that one plan's joints arrive one by one).
        """
        inp = self._inp
        inp.max_velocity = (self._velocity * speed).tolist()
        trajectory = Trajectory(self._n)
        for synchronization in (inp.synchronization, Synchronization.No):
            inp.synchronization = synchronization
            for tighter in _TIGHTER:
                inp.max_acceleration = (self._acceleration * (scale**2 * tighter)).tolist()
                inp.max_jerk = (self._jerk * (scale**3 * tighter)).tolist()
                try:
                    self._otg.calculate(inp, trajectory)
                except RuckigError as exc:
                    error = exc
                else:
                    return trajectory
        lines = str(error).strip().splitlines()
        raise MotionPlanError(lines[0] if lines else "ruckig failed") from error

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
