"""What the Cartesian verbs do: the tool, IK, and moves to a tool pose.

IK solves and line plans run on the worker's thread (``Services.worker``), so
the handlers are coroutines: the connection's reply, and its later lines,
wait for them while every other client is served.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import UnknownMarker
from ...ik.chain import PointTarget, Target
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.cartesian import Ik, LinearSpeed, MoveL, MoveTo, PoseValues, Tool
from ...robot.frames import in_base, wxyz_se3
from ..guarded import unstopped
from ..straight import plan_straight, play_straight, solve

if TYPE_CHECKING:
    from ..session import Session


@handler(Tool)
def tool(session: Session, command: Tool) -> str:
    if command.pose is None:
        return replies.ok(session.pose_text(session.state.tool))
    session.world.set_tool(session.state.name, session.pose_se3(command.pose))
    return replies.OK


@handler(Ik)
async def ik(session: Session, command: Ik) -> str:
    target = _target(session, command.pose)
    return replies.ok(replies.numbers(session.from_si(await solve(session, target))))


@handler(MoveTo)
async def moveto(session: Session, command: MoveTo) -> str:
    if command.pose is None:
        markers = session.state.markers
        index = command.marker or 0
        if not 0 < index <= len(markers):
            raise UnknownMarker(index, len(markers))
        marker = markers[index - 1]
        target = in_base(session.state.base, wxyz_se3(marker.position, marker.wxyz))
    else:
        target = _target(session, command.pose)
    q = await unstopped(session, solve(session, target))
    return await _reply(session.go(q))


@handler(MoveL)
async def movel(session: Session, command: MoveL) -> str:
    plan = await plan_straight(session, _target(session, command.pose))
    return await _reply(play_straight(session, plan))


@handler(LinearSpeed)
def lspeed(session: Session, command: LinearSpeed) -> str:
    if command.m_s is None:
        return replies.ok(replies.numbers([session.lspeed]))
    session.lspeed = command.m_s
    return replies.OK


def _target(session: Session, pose: PoseValues) -> Target:
    """A pose as the connection wrote it; ``x,y,z`` alone is a point (any orientation)."""
    return PointTarget.at(pose) if len(pose) == 3 else session.pose_se3(pose)


async def _reply(reply: Reply) -> str:
    return reply if isinstance(reply, str) else await reply
