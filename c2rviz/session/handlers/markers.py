"""What the marker verbs do: clear, mark, color/rgb, marker."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.markers import Clear, Color, Mark, MarkerShape

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Clear)
def clear(session: Session, command: Clear) -> Reply:
    session.world.clear_markers(session.state.name)
    return session.go(session.robot.home)


@handler(Mark)
def mark(session: Session, command: Mark) -> str:
    pose = None if command.pose is None else session.pose_se3(command.pose)
    session.world.add_marker(
        pose, session.rgb, session.shape, session.state.name, in_world=command.in_world
    )
    return replies.OK


@handler(Color)
def color(session: Session, command: Color) -> str:
    session.rgb = command.rgb
    return replies.OK


@handler(MarkerShape)
def marker_shape(session: Session, command: MarkerShape) -> str:
    session.shape = command.shape
    return replies.OK
