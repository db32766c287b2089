"""What the cell verbs do: switch a connection's robot, list the robots."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...protocol import replies
from ...protocol.registry import handler
from ...protocol.verbs.cell import RobotChoice, RobotsList

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


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
