"""What the verbs that show what happens do: ``watch``, ``unwatch``, ``trail``, ``ghost``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...protocol import replies
from ...protocol.registry import handler
from ...protocol.verbs.observe import Ghost, Trail, Unwatch, Watch

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Watch)
def watch(session: Session, command: Watch) -> str:
    session.services.watch.watch(session, command.hz)
    session.listens = True  # only listens from now on, until its next line
    return replies.OK


@handler(Unwatch)
def unwatch(session: Session, command: Unwatch) -> str:
    session.services.watch.unwatch(session)
    return replies.OK


@handler(Trail)
def trail(session: Session, command: Trail) -> str:
    keeper = session.services.trails
    robot = session.state.name
    if command.action is None:
        on = robot in keeper.trails
        return replies.ok(f"on {len(keeper.trails[robot])}" if on else "off")
    if command.action == "on":
        keeper.start(robot)
    elif command.action == "off":
        keeper.stop(robot)
    else:
        keeper.clear(robot)
    return replies.OK


@handler(Ghost)
def ghost(session: Session, command: Ghost) -> str:
    state = session.state
    if command.shown is None:
        return replies.ok("on" if state.ghost else "off")
    session.world.set_ghost(state.name, command.shown)
    return replies.OK
