"""What the gripper verb does: the fingers to an opening, travelling as ``motion`` says,
by the grasp rule for parts (``Session.grip``, ``calls.grip``: every door's grip)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import NoGripper
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.gripper import Grip

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Grip)
def grip(session: Session, command: Grip) -> Reply:
    state, grips = session.state, session.world.grips
    if state.robot.gripper is None:
        raise NoGripper(state.name)
    if command.opening is None:
        return replies.ok(replies.numbers([grips.now(state)]))
    return session.grip(command.opening)
