"""Straight-line tool motion: the joint path that keeps the tool on a segment.

The tool point moves on the straight segment from its pose at ``q0`` to the
goal while its orientation turns by slerp (or, for a ``PointTarget`` goal, is
left free); both progress with one parameter ``s`` from 0 to 1. Each waypoint
is solved from the one before (warm start, extrapolated along the path, so one
Newton step usually does), so the path is continuous; where joints move fast
for little tool motion the step is halved, and where even a tiny step cannot
follow the line (a joint at its limit, a singularity) the whole line is refused
before anything moves. A goal beyond the arm's reach is refused before any
step. Pure: time enters only through the speeds given to
``StraightLine.timestamps``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError
from .chain import Goal, PointTarget, Target, goal_in_world
from .solver import IkSolver


class LineBlocked(C2rvizError):
    """The tool cannot follow the straight line all the way.

    Attributes:
        fraction: How far along the line the last good waypoint is (0..1).
        q: Chain values at that waypoint [rad or m].
        joint: The joint that reaches its limit there, if that is the cause.
        joint_count: For an arm of fewer than 6 joints that cannot hold the
            line's poses, its joint count; None otherwise.

    With neither ``joint`` nor ``joint_count``, the arm passes a singularity.
    """

    def __init__(
        self,
        fraction: float,
        q: Sequence[float],
        joint: str | None = None,
        joint_count: int | None = None,
    ) -> None:
        self.fraction = fraction
        self.q = tuple(q)
        self.joint = joint
        self.joint_count = joint_count
        if joint is not None:
            reason = f"{joint} reaches its limit"
        elif joint_count is not None:
            reason = f"the tool leaves the poses {joint_count} joints can reach"
        else:
            reason = "passes a singularity"
        percent = math.floor(fraction * 100)
        super().__init__(f"straight line blocked at {percent}% of the way: {reason}")


@dataclass(frozen=True)
class LineWaypoint:
    """One point of the joint path.

    Attributes:
        s: Fraction of the way along the line (0 at the start, 1 at the goal).
        q: Chain values there [rad or m].
    """

    s: float
    q: tuple[float, ...]


def interpolate(start: pin.SE3, goal: pin.SE3, s: float) -> pin.SE3:
    """The pose a fraction ``s`` of the way: position on the segment, orientation by slerp."""
    rotation = start.rotation @ pin.exp3(s * pin.log3(start.rotation.T @ goal.rotation))
    return pin.SE3(rotation, start.translation + s * (goal.translation - start.translation))


@dataclass(frozen=True)
class StraightLine:
    """A planned straight line: its two tool poses and the joint path between.

    Attributes:
        start: Tool pose at ``s = 0`` in the base frame.
        goal: Tool pose at ``s = 1`` in the base frame.
        waypoints: The joint path, ``s`` increasing from 0 to 1.
    """

    start: pin.SE3
    goal: pin.SE3
    waypoints: tuple[LineWaypoint, ...]

    @property
    def length_m(self) -> float:
        """Distance the tool point travels [m]."""
        return float(np.linalg.norm(self.goal.translation - self.start.translation))

    @property
    def angle_rad(self) -> float:
        """Angle the tool turns through [rad]."""
        return float(np.linalg.norm(pin.log3(self.start.rotation.T @ self.goal.rotation)))

    def pose_at(self, s: float) -> pin.SE3:
        """Tool pose a fraction ``s`` of the way, in the base frame."""
        return interpolate(self.start, self.goal, s)

    def timestamps(
        self,
        speed_m_s: float,
        joint_velocity_limits: Sequence[float],
        angular_speed_rad_s: float = math.inf,
    ) -> tuple[float, ...]:
        """Time of each waypoint [s], from 0, for constant speeds between waypoints.

        Each segment takes the longest of: its length at ``speed_m_s``, its
        turn at ``angular_speed_rad_s``, and each joint's change at its
        velocity limit; so the tool never exceeds either speed and the line
        slows down where a joint cannot keep up. Accelerations are not bounded.

        Args:
            speed_m_s: Tool point speed [m/s], > 0.
            joint_velocity_limits: Per chain joint [rad/s or m/s], > 0 (inf: none).
            angular_speed_rad_s: Tool turning speed [rad/s], > 0 (inf: none).
        """
        limits = np.asarray(joint_velocity_limits, dtype=float)
        if speed_m_s <= 0 or angular_speed_rad_s <= 0 or (limits <= 0).any():
            raise ValueError("speeds and joint velocity limits must be positive")
        length, angle = self.length_m, self.angle_rad
        times = [0.0]
        for before, after in zip(self.waypoints, self.waypoints[1:]):
            ds = after.s - before.s
            joint = np.abs(np.subtract(after.q, before.q)) / limits
            duration = max(
                ds * length / speed_m_s, ds * angle / angular_speed_rad_s, float(joint.max())
            )
            times.append(times[-1] + duration)
        return tuple(times)


def plan_line(
    ik: IkSolver,
    q0: Sequence[float],
    goal: Target,
    tool: pin.SE3 | None = None,
    *,
    step_m: float = 0.005,
    step_rad: float = math.radians(1.0),
    max_joint_step: float = 0.1,
    min_step_m: float = 5e-5,
) -> StraightLine:
    """The joint path that moves the tool from its pose at ``q0`` straight to ``goal``.

    Waypoints are at most ``step_m`` and ``step_rad`` of tool motion apart;
    a step that would move a joint more than ``max_joint_step`` is halved,
    down to ``min_step_m`` (and a turn as small in proportion), where the
    line is blocked. Each waypoint's descent starts from the path extrapolated
    from the two before it, so most take one Newton step.

    A ``PointTarget`` goal leaves the orientation free all along: the tool
    point keeps to the segment while the joints move least (so the
    orientation drifts only as the arm needs; an arm of under 6 joints can
    follow such lines). The returned line's ``goal`` is then the pose reached,
    and ``pose_at`` turns by slerp between the start's and that orientation,
    an approximation of the path's (its positions are exact).

    Args:
        ik: The robot's solver.
        q0: Chain values at the start [rad or m], within the limits.
        goal: Tool pose at the end, in the base frame, or a ``PointTarget``.
        tool: Tool offset from the end-effector link (identity when None).
        step_m: Largest tool travel between waypoints [m].
        step_rad: Largest tool turn between waypoints [rad].
        max_joint_step: Largest joint change between waypoints [rad or m].
        min_step_m: Smallest step tried before the line is called blocked [m].

    Returns:
        The line, its waypoints from ``s = 0`` (``q0``) to ``s = 1``.

    Raises:
        LineBlocked: a joint reaches its limit, the arm passes a singularity,
            or (under 6 joints) the line leaves the poses the arm can reach.
        Unreachable: the goal itself cannot be reached.
    """
    chain, newton = ik.chain, ik.newton
    start = ik.tool_pose(q0, tool)  # also puts the tool on the chain
    point = isinstance(goal, PointTarget)
    end = goal_in_world(goal, chain.base_placement)
    ik.check_reach(end)  # far beyond reach: refused at once
    world_start = chain.base_placement * start
    p0, rotation0 = world_start.translation, world_start.rotation
    travel = end.position - p0
    turn = np.zeros(3) if end.rotation is None else pin.log3(rotation0.T @ end.rotation)
    length, angle = float(np.linalg.norm(travel)), float(np.linalg.norm(turn))
    count = max(1, math.ceil(max(length / step_m, angle / step_rad)))
    nominal = 1.0 / count
    smallest = nominal * min(1.0, min_step_m / step_m)  # as small a turn, in proportion
    q = tuple(float(v) for v in q0)
    here = chain.to_model(q)
    model, lower, upper = chain.model, chain.lower, chain.upper
    simple = model.nq == model.nv  # no (cos, sin) joint: configurations add and subtract
    before: tuple[float, np.ndarray] | None = None  # the waypoint before, for the predictor
    waypoints = [LineWaypoint(0.0, q)]
    s, ds = 0.0, nominal
    while s < 1.0:
        s_next = s + ds if s + ds < 1.0 - 1e-9 else 1.0
        rotation = None if point else rotation0 @ pin.exp3(s_next * turn)
        target = Goal(p0 + s_next * travel, rotation)
        guess = here
        if before is not None:  # the path so far, extrapolated: errors of order ds^2
            ratio = (s_next - s) / (s - before[0])
            if simple:
                guess = here + ratio * (here - before[1])
            else:
                guess = pin.integrate(model, here, ratio * pin.difference(model, before[1], here))
            guess = np.minimum(np.maximum(guess, lower), upper)
        reached = newton.descend(guess, target, ik.settings.max_iterations, exact=s_next == 1.0)
        change = reached.q - here if simple else pin.difference(model, here, reached.q)
        if reached.ok and float(np.abs(change).max()) <= max_joint_step:
            before = (s, here)
            s, q, here = s_next, chain.to_chain(reached.q, q), reached.q
            waypoints.append(LineWaypoint(s, q))
            ds = min(nominal, 2 * ds)
            continue
        if ds > smallest:
            ds /= 2
            continue
        ik.solve(goal, q0, tool)  # an unreachable goal is reported as such, not as a block
        if reached.ok:  # there, but only by a jump: the arm turns over a singularity
            raise LineBlocked(s, q)
        joint = _joint_at_limit(ik, chain.to_chain(reached.q, q))
        # An arm of under 6 joints reaches a thin set of poses; a line leaves it.
        few = ik.robot.n if joint is None and ik.robot.n < 6 and not point else None
        raise LineBlocked(s, q, joint, few)
    if point:  # the orientation was free: the line ends where the joints took it
        return StraightLine(start, ik.tool_pose(q, tool), tuple(waypoints))
    return StraightLine(start, goal, tuple(waypoints))


def _joint_at_limit(ik: IkSolver, q: Sequence[float], tolerance: float = 1e-3) -> str | None:
    """The chain joint nearest its limit when within ``tolerance`` [rad or m], else None."""
    robot = ik.robot
    gaps = [min(v - lo, hi - v) for v, lo, hi in zip(q, robot.lower, robot.upper)]
    index = int(np.argmin(gaps))
    return robot.joint_names[index] if gaps[index] <= tolerance else None
