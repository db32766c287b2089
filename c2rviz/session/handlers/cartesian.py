"""What the Cartesian verbs do: the tool, IK, and moves to a tool pose.

IK solves and line plans run on the worker's thread (``Services.worker``), so
the handlers are coroutines: the connection's reply, and its later lines,
wait for them while every other client is served.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ArmMoved, UnknownMarker
from ...ik.line import plan_line
from ...ik.target import PointTarget, Target
from ...motion.line_play import LinePlay, brake_limits, ramp_limits
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.cartesian import Ik, LinearSpeed, MoveL, MoveTo, PoseValues, Tool
from ...robot.frames import in_base, wxyz_se3
from ..guarded import checked_move

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Tool)
def tool(session: Session, command: Tool) -> str:
    if command.pose is None:
        return replies.ok(session.pose_text(session.state.tool))
    session.world.set_tool(session.state.name, session.pose_se3(command.pose))
    return replies.OK


@handler(Ik)
async def ik(session: Session, command: Ik) -> str:
    target = _target(session, command.pose)
    return replies.ok(replies.numbers(session.from_si(await _solve(session, target))))


@handler(MoveTo)
async def moveto(session: Session, command: MoveTo) -> str:
    if command.pose is None:
        markers = session.state.markers
        index = command.marker or 0
        if not 0 < index <= len(markers):
            raise UnknownMarker(index, len(markers))
        marker = markers[index - 1]
        q = await _solve(
            session, in_base(session.state.base, wxyz_se3(marker.position, marker.wxyz))
        )
    else:
        q = await _solve(session, _target(session, command.pose))
    return await _reply(session.go(q))


@handler(MoveL)
async def movel(session: Session, command: MoveL) -> str:
    state, world = session.state, session.world
    if session.travel.active:
        raise ArmMoved("movel starts from rest: send wait (or stop) first")
    start = state.q
    goal, tool_offset = _target(session, command.pose), state.tool
    worker = session.services.worker
    solver = worker.ik_solver(state)
    line = await worker.run(lambda: plan_line(solver, start, goal, tool_offset))
    if state.q != start or session.travel.active:
        raise ArmMoved("the arm moved while the line was planned: send movel again")
    qs = np.array([waypoint.q for waypoint in line.waypoints])
    allowed: frozenset[tuple[str, str]] = frozenset()
    if session.guard:  # the whole line, off the loop
        checked, _ = await checked_move(session, [qs[-1]], path_from=qs)
        allowed = checked.allowed
    if session.motion == "off":
        session.world.set_q(line.waypoints[-1].q, state.name, session.source)
        return replies.OK
    fraction, limits = session.speed / 100.0, session.travel.motion.limits
    times = line.timestamps(session.lspeed, [v * fraction for v in limits.velocity])
    ramp = ramp_limits(limits, fraction)
    play = LinePlay(world.clock.now(), times, qs, *ramp, brake=brake_limits(limits, fraction))
    arrival = world.travels.play(state, play, session.source, session.motion == "on")
    if session.guard:
        session.services.guards.watch(state.name, play, allowed, session.source, session.resolution)
    return replies.OK if arrival is None else await arrival


@handler(LinearSpeed)
def lspeed(session: Session, command: LinearSpeed) -> str:
    if command.m_s is None:
        return replies.ok(replies.numbers([session.lspeed]))
    session.lspeed = command.m_s
    return replies.OK


def _target(session: Session, pose: PoseValues) -> Target:
    """A pose as the connection wrote it; ``x,y,z`` alone is a point (any orientation)."""
    return PointTarget.at(pose) if len(pose) == 3 else session.pose_se3(pose)


async def _solve(session: Session, target: Target) -> Sequence[float]:
    state, worker = session.state, session.services.worker
    seed, tool_offset = session.now(), state.tool
    solver = worker.ik_solver(state)
    return await worker.run(lambda: solver.solve(target, seed, tool_offset))


async def _reply(reply: Reply) -> str:
    return reply if isinstance(reply, str) else await reply
