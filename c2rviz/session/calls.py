"""The work of ``Session``'s typed calls: moves planned before they move, checks, grips;
and a move's IK and the tool's straight line, planned off the loop and played, which
the Cartesian verbs (``handlers.arm``) share with them.

First the straight line: typed on ``MoveSession`` (what of ``Session`` it uses), so the
typed calls and the verbs reach it without a cycle through the session module.

Then the calls. A ``Plan`` is a move solved (a straight line also planned and checked)
with nothing moved yet; ``play`` moves it. ``plan_through`` plans several, each from
the end of the one before, and with the guard checks every joint-space leg after
the first off the event loop, on the session's worker, one leg per job (the first
is checked as it starts); an error names the waypoint (1-based, as CRCL counts).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..collision.model import segment
from ..errors import ArmMoved, C2rvizError, NoGripper, PathCollides
from ..ik.chain import Target
from ..ik.line import StraightLine, plan_line
from ..motion.path_play import LinePlay, TrajectoryPlay, brake_limits, ramp_limits
from ..motion.trajectory import PlannedTrajectory
from ..planning import MoveChecker, MoveRequest, first_blocked, path_points
from ..planning.errors import STOPPED
from ..protocol import replies
from ..protocol.registry import Reply
from ..robot.model import Robot
from ..world.part_rules import SUCTION_BELOW, is_vacuum
from .guarded import GuardedSession, checked_move, checker_of, request, unstopped


class MoveSession(GuardedSession, Protocol):
    """What a planned move needs of its session (``session.Session``), beyond a guarded
    move's."""

    robot: Robot
    guard: bool
    lspeed: float

    def go(self, q: Sequence[float], speed: float | None = None) -> Reply: ...


@dataclass(frozen=True)
class StraightPlan:
    """A straight tool line planned from the arm at rest at ``start`` [rad or m]."""

    start: tuple[float, ...]
    waypoints: list[tuple[float, ...]]
    line: StraightLine
    allowed: frozenset[tuple[str, str]] = frozenset()
    """Pairs touching at the start that the line may leave (the guard's)."""


async def plan_straight(
    session: MoveSession, goal: Target, start: Sequence[float] | None = None
) -> StraightPlan:
    """Plan the tool's straight line from where the arm rests (or from ``start`` [rad or
    m], the end of a line planned before) to ``goal`` (base frame, SI; a point alone leaves
    the orientation free), checked off the loop by the guard when it is on; nothing moves
    yet (``play_straight`` moves).

    Raises:
        ArmMoved: the arm moves (or moved while the line was planned).
        C2rvizError: the line leaves the reach, or (guarded) collides.
    """
    state = session.state
    if start is None and session.travel.active:
        raise ArmMoved("movel starts from rest: send wait (or stop) first")
    first, tool_offset = tuple(state.q if start is None else start), state.tool
    worker = session.services.worker
    solver = worker.ik_solver(state)
    work = worker.run(lambda: plan_line(solver, first, goal, tool_offset), owner=session)
    line = await (unstopped(session, work) if start is None else work)
    if start is None and (state.q != first or session.travel.active):
        raise ArmMoved("the arm moved while the line was planned: send movel again")
    waypoints = [waypoint.q for waypoint in line.waypoints]
    allowed: frozenset[tuple[str, str]] = frozenset()
    if session.guard:  # the whole line, off the loop
        checked, _ = await checked_move(session, [waypoints[-1]], path_from=np.array(waypoints))
        allowed = checked.allowed
    return StraightPlan(first, waypoints, line, allowed)


def play_straight(session: MoveSession, plan: StraightPlan, speed: float | None = None) -> Reply:
    """Move along a planned line as ``motion`` says (at once, or travelling at ``lspeed``
    within ``speed`` % of the joints' limits; None: the session's)."""
    state, world = session.state, session.world
    if session.motion == "off":
        world.set_q(plan.waypoints[-1], state.name, session.source)
        return replies.OK
    fraction = (session.speed if speed is None else speed) / 100.0
    limits = session.travel.motion.limits
    times = plan.line.timestamps(session.lspeed, [v * fraction for v in limits.velocity])
    ramp = ramp_limits(limits, fraction)
    brake = brake_limits(limits, fraction)
    play = LinePlay(world.clock.now(), times, np.array(plan.waypoints), *ramp, brake=brake)
    arrival = world.travels.play(state, play, session.source, session.motion == "on")
    if session.guard:
        session.services.guards.watch(
            state.name, play, plan.allowed, session.source, session.resolution
        )
    return replies.OK if arrival is None else arrival


async def solve(
    session: MoveSession, target: Target, seed: Sequence[float] | None = None
) -> Sequence[float]:
    """The joints [rad or m] that put the tool point at ``target`` (base frame, SI; a point
    alone: any orientation), from
    ``seed`` (default: the arm's joints now), on the worker's thread.

    Raises:
        C2rvizError: the pose is out of reach (naming how far).
    """
    state, worker = session.state, session.services.worker
    first, tool_offset = (session.now() if seed is None else seed), state.tool
    solver = worker.ik_solver(state)
    return await worker.run(lambda: solver.solve(target, first, tool_offset), owner=session)


MAX_TRAJECTORY_CHECKS = 2000
"""Most instants of a timed trajectory checked for collisions (one per frame, or fewer)."""


@dataclass(frozen=True)
class Plan:
    """A move to a tool pose, solved (and, for a straight line, planned and checked);
    nothing has moved yet (``Session.play`` moves)."""

    goal: tuple[float, ...]
    """The joints at its end [rad or m]."""
    straight: StraightPlan | None = None
    """The tool's straight line, or None: through joint space."""


class WaypointError(C2rvizError):
    """A waypoint of a move through several (1-based, as CRCL counts) that fails."""

    def __init__(self, index: int, count: int, cause: C2rvizError) -> None:
        self.index, self.count, self.cause = index, count, cause
        super().__init__(f"waypoint {index} of {count}: {cause}")


async def plan_to(
    session: MoveSession,
    target: Target,
    *,
    straight: bool = False,
    start: Sequence[float] | None = None,
) -> Plan:
    """``Session.plan_to``: see there."""
    if straight:
        line = await plan_straight(session, target, start)
        return Plan(tuple(line.waypoints[-1]), line)
    if start is None:  # a plan of a move now: refused as the move would be (a stop)
        return Plan(tuple(await unstopped(session, solve(session, target))))
    return Plan(tuple(await solve(session, target, start)))


async def plan_through(
    session: MoveSession, targets: Sequence[Target], *, straight: bool = False
) -> list[Plan]:
    """``Session.plan_through``: see there."""
    plans: list[Plan] = []
    count = len(targets)
    start: Sequence[float] | None = None
    for index, target in enumerate(targets, start=1):
        try:
            plan = await plan_to(session, target, straight=straight, start=start)
        except ArmMoved:
            raise
        except C2rvizError as error:
            raise WaypointError(index, count, error) from error
        plans.append(plan)
        start = plan.goal
    if not straight and session.guard:  # the first leg is checked as it starts
        worker, robot = session.services.worker, session.robot
        for index, (before, after) in enumerate(zip(plans, plans[1:]), start=2):
            check = _path_check(session, after.goal, segment(robot, before.goal, after.goal))
            try:
                await worker.run(check)
            except C2rvizError as error:
                raise WaypointError(index, count, error) from error
    return plans


def play(session: MoveSession, plan: Plan, speed: float | None) -> Reply:
    """``Session.play``: see there."""
    line = plan.straight
    if line is None:
        return session.go(plan.goal, speed)
    if session.travel.active or session.state.q != line.start:
        raise ArmMoved("the arm moved (another door drives it) between the waypoints")
    return play_straight(session, line, speed)


def play_trajectory(
    session: MoveSession, planned: PlannedTrajectory, checked: bool = False
) -> Reply:
    """``Session.play_trajectory``: see there."""
    world, state = session.world, session.state
    if session.guard and not checked:
        _trajectory_check(session, planned, MoveChecker())()
    world.travels.play(state, TrajectoryPlay(planned, world.clock.now()), session.source, False)
    return replies.OK


async def check_trajectory(session: MoveSession, planned: PlannedTrajectory) -> None:
    """``Session.check_trajectory``: see there."""
    if session.guard:
        await session.services.worker.run(_trajectory_check(session, planned), owner=session)


def _trajectory_check(
    session: MoveSession, planned: PlannedTrajectory, checker: MoveChecker | None = None
) -> Callable[[], None]:
    """The guard's check of ``planned`` against the cell now: at most
    ``MAX_TRAJECTORY_CHECKS`` instants and every knot, sampled where it runs (``checker``
    given: here; else on the worker's thread, with its own checker)."""
    count = min(MAX_TRAJECTORY_CHECKS, max(2, int(planned.duration / session.world.frame_s) + 1))
    q = tuple(planned.sample(planned.duration).tolist())
    start = session.now()
    asked = request(session, start, [q])
    chosen = checker if checker is not None else checker_of(session.services.worker)

    def check() -> None:
        times = np.unique(
            np.concatenate([np.linspace(0.0, planned.duration, count), planned.times])
        )
        path = np.array([planned.sample(float(s)) for s in times], dtype=float)
        _check(chosen, asked, start, path, False, q)

    return check


def check_path(
    session: MoveSession, q: Sequence[float], path: Sequence[Sequence[float]] = ()
) -> None:
    """``Session.check_path``, here on the event loop: see there."""
    _path_check(session, q, path, MoveChecker())()


def _path_check(
    session: MoveSession,
    q: Sequence[float],
    path: Sequence[Sequence[float]],
    checker: MoveChecker | None = None,
) -> Callable[[], None]:
    """The check of ``check_path``, with what it checks against taken now: run it here
    (``checker`` given) or on the worker's thread (its own checker)."""
    at_target = session.motion == "off" and not path
    start = session.now()
    asked = request(session, start, [q])
    chosen = checker if checker is not None else checker_of(session.services.worker)
    waypoints = np.array([q] if at_target else (path if path else [start, q]), dtype=float)
    return functools.partial(_check, chosen, asked, start, waypoints, at_target, tuple(q))


def _check(
    checker: MoveChecker,
    asked: MoveRequest,
    start: tuple[float, ...],
    waypoints: np.ndarray,
    at_target: bool,
    q: tuple[float, ...],
) -> None:
    valid = checker.checker(asked)
    allowed = valid.batch.colliding(start)
    points = waypoints if at_target else path_points(valid, waypoints)
    found = first_blocked(valid, points, allowed)
    if found is not None:
        index, (first, second) = found
        fraction = index / max(len(points) - 1, 1)
        raise PathCollides(first, second, fraction, at_target, target=q)


def grip(session: MoveSession, opening: float) -> Reply:
    """``Session.grip``: see there. Closing on a part takes it by the grasp rule
    (``world/part_rules.py``, docs/parts.md): the fingers stop where they touch it and the reply
    says that opening (``ok 0.433``); opening them lets go of what they hold. A vacuum
    gripper's suction turns on below ``SUCTION_BELOW`` (taking a part at the cup replies
    ``ok held``) and off from it, letting go."""
    state, grips = session.state, session.world.grips
    if state.robot.gripper is None:
        raise NoGripper(state.name)
    grips.rules.refuse(state)  # a stop refuses the fingers too, before a part is touched
    reply = replies.OK
    parts = session.world.parts
    now = grips.now(state)
    if is_vacuum(state.robot.gripper):
        if opening >= SUCTION_BELOW:
            parts.release(state.name)
        elif parts.suck(state.name) is not None:
            reply = replies.ok("held")
    elif parts.parts.held_by(state.name):
        if opening > state.opening_target:
            parts.release(state.name)
        else:  # the fingers stay on the part they hold
            opening = max(opening, state.opening_target)
    elif opening < now:
        opening, taken = parts.close(state.name, now, opening)
        if taken is not None:
            reply = replies.ok(replies.numbers([opening]))
    if session.motion == "off":
        grips.set(state, opening, session.source)
        return reply
    arrival = grips.go(state, opening, session.source, session.motion == "on", reply)
    return reply if arrival is None else arrival


def brake(session: MoveSession, fingers: bool) -> Reply:
    """``Session.stop``: see there. A plan this session is searching stops too."""
    session.services.worker.cancel(session, STOPPED)
    if fingers:
        session.world.grips.stop(session.state, session.source)
    rest = session.world.travels.stop(session.state, session.source)
    return replies.OK if rest is None else rest
