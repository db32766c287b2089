"""What the arm's verbs do (``protocol.verbs.arm``): the tool, IK and moves to a tool pose
(``tool``, ``ik``, ``moveto``, ``movel``, ``lspeed``); the cell's robots (``robot``,
``robots``); this connection's ``motion`` mode and ``speed``, ``stop``, ``wait``,
``target``, ``status``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import UnknownMarker
from ...ik.chain import PointTarget
from ...ik.chain import Target as ToolTarget
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.arm import (
    Ik,
    LinearSpeed,
    MotionMode,
    MoveL,
    MoveTo,
    PoseValues,
    RobotChoice,
    RobotsList,
    Speed,
    Status,
    Stop,
    Target,
    Tool,
    Wait,
)
from ...robot.frames import in_base, wxyz_se3
from ..calls import plan_straight, play_straight, solve
from ..guarded import unstopped

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


def _target(session: Session, pose: PoseValues) -> ToolTarget:
    """A pose as the connection wrote it; ``x,y,z`` alone is a point (any orientation)."""
    return PointTarget.at(pose) if len(pose) == 3 else session.pose_se3(pose)


async def _reply(reply: Reply) -> str:
    return reply if isinstance(reply, str) else await reply


@handler(RobotChoice)
def robot(session: Session, command: RobotChoice) -> str:
    if command.name is None:
        return replies.ok(session.state.name)
    session.select(command.name)
    return replies.OK


@handler(RobotsList)
def robots(session: Session, command: RobotsList) -> str:
    return replies.ok(
        ",".join(
            name if state.port is None else f"{name}:{state.port}"
            for name, state in session.world.robots.items()
        )
    )


@handler(MotionMode)
def motion_mode(session: Session, command: MotionMode) -> str:
    if command.mode is None:
        return replies.ok(session.motion)
    session.motion = command.mode
    return replies.OK


@handler(Speed)
def speed(session: Session, command: Speed) -> str:
    if command.percent is None:
        return replies.ok(replies.numbers([session.speed]))
    session.speed = command.percent
    return replies.OK


@handler(Stop)
def stop(session: Session, command: Stop) -> Reply:
    return session.stop()


@handler(Wait)
def wait(session: Session, command: Wait) -> Reply:
    at_rest = session.world.travels.rest(session.state)
    return replies.OK if at_rest is None else at_rest


@handler(Target)
def target(session: Session, command: Target) -> str:
    return replies.ok(replies.numbers(session.from_si(session.state.target)))


@handler(Status)
def status(session: Session, command: Status) -> str:
    left = session.world.travels.seconds_left(session.state)
    return replies.ok(f"moving {left:.3f}" if session.travel.active else "idle")
