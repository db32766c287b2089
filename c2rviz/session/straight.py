"""A move's IK and the tool's straight line, planned off the loop and played: what the
Cartesian verbs (``handlers.cartesian``) and the typed calls (``calls``: ``plan_to``,
``play``) share.

Typed on ``MoveSession`` (what of ``Session`` they use), so the typed calls reach them
without a cycle through the session module.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import ArmMoved
from ..ik.chain import Target
from ..ik.line import StraightLine, plan_line
from ..motion.path_play import LinePlay, brake_limits, ramp_limits
from ..protocol import replies
from ..protocol.registry import Reply
from ..robot.model import Robot
from .guarded import GuardedSession, checked_move, unstopped

__all__ = ["MoveSession", "StraightPlan", "plan_straight", "play_straight", "solve"]


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
