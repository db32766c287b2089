"""Text command lines from rosbridge clients: one ``Session`` per client and robot, in order.

A line published on ``[NS]/c2rviz/command`` or sent to the service of that name
runs through the session of its client (``rosbridge HOST:PORT``) for that
robot, exactly as a line on the text port: parsed, checked, guarded, noted in
the world's commands. The session keeps its modes (``degrees``, ``motion on``,
``speed``...) between lines, as a TCP connection's does. Lines run in the order
they came, each after the previous one's reply (a reply may wait: ``sleep``, a
move with ``motion on``), while the client's other requests go on. At most
``MAX_WAITING`` lines wait behind a reply; one more is refused.

A line that runs at once (nothing before it waits) and is refused raises, so
the publishing client gets a ``status`` error as well. ``bye`` starts the
session afresh (the websocket stays open); ``quit`` stops the program, as on
the text port.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

from ...errors import C2rvizError
from ...protocol import replies
from ...protocol.registry import Reply
from ...session.services import Services
from ...session.session import Session

__all__ = ["MAX_WAITING", "CommandLines", "CommandRefused", "LineQueue"]

log = logging.getLogger("c2rviz.rosbridge")

MAX_WAITING = 100
"""Lines of one client and robot that may wait behind a reply."""

Answer = Callable[[str, bool], None]
"""Takes a line's reply text and whether it was not an error."""


class CommandRefused(C2rvizError):
    """A line refused at once: its reply's problem."""


@dataclass(eq=False)
class _Waiting:
    line: str
    answer: Answer


class LineQueue:
    """The lines of one client for one robot, run in order through its session."""

    def __init__(self, make_session: Callable[[], Session], on_quit: Callable[[], None]) -> None:
        self.make_session = make_session
        self.session = make_session()
        self.on_quit = on_quit
        self._waiting: deque[_Waiting] = deque()
        self._task: asyncio.Task[None] | None = None

    @property
    def busy(self) -> bool:
        """A reply is awaited, or lines wait."""
        return self._task is not None

    def take(self, line: str, answer: Answer) -> None:
        """Run ``line`` now if nothing waits, else after the lines before it.

        Raises:
            CommandRefused: The line ran at once and was refused (``answer`` was told too).
            C2rvizError: ``MAX_WAITING`` lines wait already.
        """
        if self._task is None:
            reply = self._run(line)
            if reply is None or isinstance(reply, str):
                self._finish(reply, answer)
                if reply is not None and reply.startswith("error:"):
                    raise CommandRefused(reply.removeprefix("error: "))
                return
            self._task = asyncio.ensure_future(self._await_then_drain(reply, answer))
            return
        if len(self._waiting) >= MAX_WAITING:
            raise C2rvizError(
                f"too many commands waiting behind a reply (limit {MAX_WAITING}); "
                "wait for /c2rviz/reply or send stop"
            )
        self._waiting.append(_Waiting(line, answer))

    async def ask(self, line: str) -> tuple[str, bool]:
        """Run ``line`` in its turn and return its reply text and whether it is not an error."""
        done: asyncio.Future[tuple[str, bool]] = asyncio.get_running_loop().create_future()

        def answer(text: str, ok: bool) -> None:
            if not done.done():
                done.set_result((text, ok))

        with contextlib.suppress(CommandRefused):  # answered already
            self.take(line, answer)
        return await done

    def close(self) -> None:
        """The client is gone: lines still waiting are dropped, a reply waited for too."""
        self._waiting.clear()
        if self._task is not None:
            self._task.cancel()

    def _run(self, line: str) -> Reply | None:
        try:
            return self.session.run(line)
        except C2rvizError as error:
            return replies.error(error)
        except Exception:  # a bug must cost one reply, never the door
            log.exception("rosbridge: internal error on %r from %s", line, self.session.source)
            return replies.error("internal error (see the server log)")

    def _finish(self, reply: str | None, answer: Answer) -> None:
        if reply is None:  # a blank or comment line: no reply, as on the text port
            answer("", True)
            return
        hangup = self.session.take_hangup()
        answer(reply, not reply.startswith("error:"))
        if hangup == "bye":
            self.session = self.make_session()
        elif hangup == "quit":
            self.on_quit()

    async def _await_then_drain(self, reply: Reply, answer: Answer) -> None:
        try:
            self._finish(await _settled(reply), answer)
            while self._waiting:
                item = self._waiting.popleft()
                now = self._run(item.line)
                if now is not None and not isinstance(now, str):
                    now = await _settled(now)
                self._finish(now, item.answer)
        finally:
            self._task = None


async def _settled(reply: Reply) -> str:
    """The text of a reply that waits (an error's text when it fails)."""
    try:
        return reply if isinstance(reply, str) else await reply
    except C2rvizError as error:
        return replies.error(error)
    except asyncio.CancelledError:
        raise
    except Exception:  # a bug must cost one reply, never the door
        log.exception("rosbridge: internal error while a reply was awaited")
        return replies.error("internal error (see the server log)")


class CommandLines:
    """Every client's line queues, by client and robot."""

    def __init__(self, services: Services, on_quit: Callable[[], None]) -> None:
        self.services = services
        self.on_quit = on_quit
        self.queues: dict[tuple[str, str], LineQueue] = {}

    def queue(self, source: str, robot: str) -> LineQueue:
        """The queue (and session) of ``source`` for ``robot``."""
        key = (source, robot)
        queue = self.queues.get(key)
        if queue is None:
            queue = self.queues[key] = LineQueue(
                partial(Session, self.services, source, robot), self.on_quit
            )
        return queue

    def session(self, source: str, robot: str) -> Session:
        """The session of ``source`` for ``robot`` (its joint inputs use its modes)."""
        return self.queue(source, robot).session

    def closed(self, source: str) -> None:
        """The client ``source`` is gone: drop its sessions."""
        for key in [k for k in self.queues if k[0] == source]:
            self.queues.pop(key).close()
