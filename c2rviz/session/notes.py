"""What the world hears of a session's commands, told from one place.

Every door's command is told to the world's observers the same way, here and
nowhere else: ``World.note`` when it is taken or refused (the page's "last
commands", the recordings' sources), ``World.refused`` with the error when it
is refused (the page's last error, a guarded target in red), and
``World.replied`` with the session's reply text once it is known (recordings
keep it). A ``Said`` is one command as its door shows it (a text line,
``/joint_command joint_s=0.5``, ``MoveToType (CommandID 3)``); each of the three
is told at most once. A line's reply, ``ok`` or error, passes ``late`` here too: a
latency fault delays them alike (docs/faults.md).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Sequence
from typing import Protocol, overload

from ..errors import C2rvizError, MotionInterrupted
from ..protocol import replies
from ..protocol.grammar import ForeignProtocol
from ..protocol.registry import Reply
from ..world.state import RobotState
from ..world.world import World


class Session(Protocol):
    """What the notes need of the session whose command they tell (``session.Session``)."""

    world: World
    source: str
    state: RobotState
    hangup: str | None


INTERNAL = replies.error("internal error (see the server log)")
"""The reply to a command that met a bug (the log has the traceback)."""


class Said:
    """One command of ``session`` as its door shows it (``text``), told to the world once.

    Args:
        session: The session the command runs on (its source and robot are named).
        text: The command as the page's "last commands" shows it.
    """

    __slots__ = ("_noted", "_refused", "_replied", "robot", "session", "text")

    def __init__(self, session: Session, text: str) -> None:
        self.session = session
        self.text = text
        self.robot: str | None = None
        """The robot it drives (None: the session's now)."""
        self._noted = self._refused = self._replied = False

    def accept(self) -> None:
        """It was taken (its reply may still be an error: a move that fails later)."""
        if not self._noted:
            self._noted = True
            session = self.session
            session.world.note(session.source, self.text, True)

    def refuse(self, error: C2rvizError) -> None:
        """It was refused with ``error`` (at once, or later: the reply of a move).

        A move stopped short (``MotionInterrupted``) is not a refusal, only an error reply;
        a ``ForeignProtocol`` line is answered by its door in its own way (no reply here)."""
        session = self.session
        if not self._noted:
            self._noted = True
            session.world.note(session.source, self.text, False)
        if not isinstance(error, MotionInterrupted) and not self._refused:
            self._refused = True
            robot = self.robot if self.robot is not None else session.state.name
            session.world.refused(robot, session.source, self.text, error)
        if not isinstance(error, ForeignProtocol):
            self.reply(replies.error(error))

    def reply(self, text: str) -> None:
        """Its reply is ``text`` (an error's too)."""
        if not self._replied:
            self._replied = True
            session = self.session
            session.world.replied(session.source, self.text, text)

    def follow(self, reply: Reply) -> Reply:
        """Tell ``reply`` now, or when it comes (an awaitable, handed back as a future that
        tells it: a refusal then as a refusal; a cancelled one reached nobody)."""
        if isinstance(reply, str):
            self.reply(reply)
            return reply
        self.robot = self.session.state.name
        later = asyncio.ensure_future(reply)
        later.add_done_callback(self._came)
        return later

    def _came(self, later: asyncio.Future[str]) -> None:
        if later.cancelled():
            return
        error = later.exception()
        if error is None:
            self.reply(later.result())
        elif isinstance(error, C2rvizError):
            self.refuse(error)
        else:
            self.reply(INTERNAL)


def recorded(session: Session, said: str | Said | None, act: Callable[[], Reply]) -> Reply:
    """``act()``'s reply, told to the world as ``said`` (a ``Said`` the door made first, to
    tell its own refusals through it too; None: the door tells it)."""
    if said is None:
        return act()
    record = said if isinstance(said, Said) else Said(session, said)
    try:
        reply = act()
    except C2rvizError as error:
        record.refuse(error)
        raise
    record.accept()
    return record.follow(reply)


def taken_all(session: Session, texts: Sequence[str], reply: str) -> None:
    """``texts`` were all taken at once, each answered ``reply`` (a run of ``joints`` lines)."""
    session.world.taken(session.source, texts, reply)


def taken(session: Session, text: str, reply: Reply) -> Reply:
    """``text`` was taken and ``reply`` is its reply: ``Said(...).accept()`` then
    ``follow(reply)``, without the record for a reply at once (the hot path). With a
    latency fault on the session's robot the reply comes late (``late``)."""
    if session.world.faults.late:
        reply = late(session, reply)
    if isinstance(reply, str):
        world, source = session.world, session.source
        world.note(source, text, True)
        world.replied(source, text, reply)
        return reply
    said = Said(session, text)
    said.accept()
    return said.follow(reply)


def refused(session: Session, text: str, error: C2rvizError) -> Reply:
    """``text`` was refused with ``error``: the world hears it now; the error is raised, or,
    with a latency fault on the session's robot, handed back as a reply that raises it late.

    Raises:
        C2rvizError: ``error``, unless it comes late.
    """
    Said(session, text).refuse(error)
    if session.world.faults.late and not isinstance(error, ForeignProtocol):
        answer = late(session, error)
        if not isinstance(answer, C2rvizError):
            return answer
    raise error


@overload
def late(session: Session, reply: Reply) -> Reply: ...
@overload
def late(session: Session, reply: C2rvizError) -> Reply | C2rvizError: ...
def late(session: Session, reply: Reply | C2rvizError) -> Reply | C2rvizError:
    """``reply`` to ``session``'s client as its robot's latency fault makes it: the one place
    every reply of a line passes, ``ok`` or error, at once or waited for (the text port's,
    rosbridge's command lines'). ``bye`` and ``quit`` are not delayed: the door closes
    after them."""
    if session.hangup is not None:
        return reply
    return session.world.faults.delayed(session.state.name, reply)
