"""What the gripper verb does: the fingers to an opening, travelling as ``motion`` says.

Closing on a part takes it by the grasp rule (``world/grasp.py``, docs/parts.md): the
fingers stop where they touch it and the reply says that opening (``ok 0.433``); opening
them lets go of what they hold. A vacuum gripper's suction turns on below
``SUCTION_BELOW`` (``grip 0``; taking a part at the cup replies ``ok held``) and off
from it (``grip 1``), letting go.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import NoGripper
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.gripper import Grip
from ...world.grasp import SUCTION_BELOW, is_vacuum

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
    opening, reply = command.opening, replies.OK
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
