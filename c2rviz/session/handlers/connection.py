"""What the connection verbs do: sleep, bye, quit."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import BadArguments
from ...protocol import replies
from ...protocol.registry import Reply, handler, usage
from ...protocol.verbs.connection import Bye, Quit, Sleep

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Sleep)
def sleep(session: Session, command: Sleep) -> Reply:
    longest = session.limits.max_sleep_s
    if command.seconds > longest:
        raise BadArguments(
            "sleep", f"{command.seconds:g} s is over the limit of {longest:g} s", usage("sleep")
        )
    return session.after(command.seconds, replies.OK)


@handler(Bye)
def bye(session: Session, command: Bye) -> str:
    session.hangup = "bye"
    return replies.BYE


@handler(Quit)
def quit_(session: Session, command: Quit) -> str:
    session.hangup = "quit"
    return replies.OK
