"""What the Cartesian verbs do: the tool, IK, and moves to a tool pose.

IK solves and line plans run on the world's solver thread (``World.solve``), so
the handlers are coroutines: the connection's reply, and its later lines,
wait for them while every other client is served.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ...errors import ArmMoved, UnknownMarker
from ...ik.line import plan_line
from ...motion.line_play import ramp_limits
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.cartesian import Ik, LinearSpeed, MoveL, MoveTo, PoseValues, Tool

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


def pose_se3(session: Session, pose: PoseValues) -> pin.SE3:
    """A pose as the connection wrote it (m; its angle unit), as an SE3."""
    x, y, z, roll, pitch, yaw = pose
    angle = session.angle_scale
    return pin.SE3(
        pin.rpy.rpyToMatrix(roll * angle, pitch * angle, yaw * angle), np.array([x, y, z])
    )


def pose_text(session: Session, placement: pin.SE3) -> str:
    """An SE3 as ``x,y,z,roll,pitch,yaw`` in the connection's units."""
    rpy = pin.rpy.matrixToRpy(placement.rotation) / session.angle_scale
    return replies.numbers([*placement.translation, *rpy])


@handler(Tool)
def tool(session: Session, command: Tool) -> str:
    if command.pose is None:
        return replies.ok(pose_text(session, session.state.tool))
    session.world.set_tool(session.state.name, pose_se3(session, command.pose))
    return replies.OK


@handler(Ik)
async def ik(session: Session, command: Ik) -> str:
    return replies.ok(replies.numbers(session.from_si(await _solve(session, command.pose))))


@handler(MoveTo)
async def moveto(session: Session, command: MoveTo) -> str:
    if command.pose is None:
        markers = session.state.markers
        index = command.marker or 0
        if not 0 < index <= len(markers):
            raise UnknownMarker(index, len(markers))
        marker = markers[index - 1]
        w, x, y, z = marker.wxyz
        in_world = pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(marker.position))
        target = (session.state.origin * session.robot.base_placement).actInv(in_world)
        q = await _solve_se3(session, target)
    else:
        q = await _solve(session, command.pose)
    return await _reply(session.go(q))


@handler(MoveL)
async def movel(session: Session, command: MoveL) -> str:
    state, world = session.state, session.world
    if state.travel.active:
        raise ArmMoved("movel starts from rest: send wait (or stop) first")
    start = state.q
    goal, tool_offset = pose_se3(session, command.pose), state.tool
    solver = world.ik_solver(state.name)
    line = await world.solve(lambda: plan_line(solver, start, goal, tool_offset))
    if state.q != start or state.travel.active:
        raise ArmMoved("the arm moved while the line was planned: send movel again")
    qs = np.array([waypoint.q for waypoint in line.waypoints])
    if session.guard:
        session.check_path(line.waypoints[-1].q, path=[waypoint.q for waypoint in line.waypoints])
    if session.motion == "off":
        session.world.set_q(line.waypoints[-1].q, state.name, session.source)
        return replies.OK
    fraction, limits = session.speed / 100.0, state.travel.motion.limits
    times = line.timestamps(session.lspeed, [v * fraction for v in limits.velocity])
    ramp = ramp_limits(limits, fraction)
    arrival = world.travels.play_line(
        state, qs, times, ramp, session.source, session.motion == "on"
    )
    return replies.OK if arrival is None else await arrival


@handler(LinearSpeed)
def lspeed(session: Session, command: LinearSpeed) -> str:
    if command.m_s is None:
        return replies.ok(replies.numbers([session.lspeed]))
    session.lspeed = command.m_s
    return replies.OK


async def _solve(session: Session, pose: PoseValues) -> Sequence[float]:
    return await _solve_se3(session, pose_se3(session, pose))


async def _solve_se3(session: Session, target: pin.SE3) -> Sequence[float]:
    state, world = session.state, session.world
    seed, tool_offset = session.now(), state.tool
    solver = world.ik_solver(state.name)
    return await world.solve(lambda: solver.solve(target, seed, tool_offset))


async def _reply(reply: Reply) -> str:
    return reply if isinstance(reply, str) else await reply
