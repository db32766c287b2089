"""How a TCP door reads its clients: a client's turn, the close, and reading ahead.

What every TCP door (the text port, CRCL) keeps alike: a client's work runs ``TURN_S``
at a time, then the other clients go first, so one client's flood delays the others by
no more than that. A door that closes a connection (a limit, ``bye``, a refusal,
shutdown) sends what is queued, ends its side and reads and drops what the client still
sends for up to ``LINGER_S`` (``close_lingering``): closing with input unread would make
the kernel reset the connection, and a reset destroys replies not yet delivered.

The text port's reading behind a reply that waits: a connection whose reply waits (a
``sleep``, a plan) holds the lines behind it, but reads on, up to ``LOOK_AHEAD_BYTES``
buffered, to see two things at once: a ``stop`` line cancels the connection's plans
(``stop_plans``; the ``stop`` itself still runs in its turn), and the end of the stream
cancels them all. ``StopScan`` remembers how far the buffer was looked at, so each byte
is decoded once; ``is_command`` tells which lines still owe a reply when the connection
closes early, and ``waited_reply`` what the client is told when the reply it waited for
comes.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Final

from ..errors import C2rvizError
from ..planning.errors import STOPPED
from ..protocol import replies
from ..protocol.framing import Line, LineFramer
from ..protocol.grammar import parse_line
from ..protocol.verbs.arm import Stop
from ..session.session import Session

TURN_S: Final = 0.002
"""Work per client per event-loop turn [s]: then the other clients go first."""
LINGER_S: Final = 2.0
"""After the close is decided, how long a client's input is read and dropped [s]."""


def close_lingering(transport: asyncio.Transport, eof: bool) -> asyncio.TimerHandle | None:
    """Send what is queued, then close without a reset.

    Unless the client has finished sending (``eof``), the door half-closes (FIN after
    the replies) and reads on; the caller drops what comes, and the connection closes
    when the client closes too, or is aborted ``LINGER_S`` after the close began.

    Args:
        transport: The connection's transport.
        eof: The client has sent all it will (nothing to linger for: it closes now).

    Returns:
        The timer that aborts the connection (cancel it once the client has closed), or
        None: the connection is closed or closing already.
    """
    if transport.is_closing():
        return None
    if eof:
        transport.close()  # nothing more will come: nothing to linger for
        return None
    try:
        transport.write_eof()
    except OSError:  # the client is already gone (ENOTCONN): nothing to deliver
        transport.abort()
        return None
    transport.resume_reading()
    return asyncio.get_running_loop().call_later(LINGER_S, transport.abort)


# The text port's reading behind a reply that waits.

log = logging.getLogger("c2rviz.server")

LOOK_AHEAD_BYTES: Final = 16384
"""Read behind a reply that waits at most [bytes], then reading pauses."""


def is_stop(line: Line) -> bool:
    """True for a ``stop`` line."""
    if not isinstance(line, str) or "stop" not in line.lower():
        return False
    try:
        return isinstance(parse_line(line), Stop)
    except C2rvizError:
        return False


def is_command(line: Line) -> bool:
    """True for a line that would get a reply (not blank, not only a comment)."""
    if not isinstance(line, str):
        return True
    try:
        return parse_line(line) is not None
    except C2rvizError:
        return True


class StopScan:
    """How far a framer's buffer has been looked at for a ``stop`` (complete lines only)."""

    def __init__(self) -> None:
        self.scanned = 0
        """Bytes of the buffer already looked at."""

    def reset(self) -> None:
        """The buffer was taken (its lines run): look again from its start."""
        self.scanned = 0

    def stop_in(self, framer: LineFramer) -> bool:
        """Whether the complete lines buffered since the last look hold a ``stop``."""
        buffer = framer.buffer
        cut = buffer.rfind(b"\n")
        if cut < self.scanned:
            return False
        fresh = framer.decode(buffer[self.scanned : cut])
        self.scanned = cut + 1
        return any(map(is_stop, fresh))


def pace_reading(transport: asyncio.Transport, buffered: int, eof: bool) -> None:
    """Pause reading once ``LOOK_AHEAD_BYTES`` wait; else read on (unless the stream ended:
    reading may have been paused by a yield or by the bound)."""
    if buffered >= LOOK_AHEAD_BYTES:
        if transport.is_reading():
            transport.pause_reading()
    elif not eof and not transport.is_reading():
        transport.resume_reading()


def stop_plans(session: Session) -> None:
    """A ``stop`` waits behind the reply: the session's plans stop now, through its
    ``stop`` if one searches, and so do the plans it sent before the ``stop``."""
    worker = session.services.worker
    if worker.planning(session):
        braked = session.stop()
        if not isinstance(braked, str):  # (the arm was moving: its rest is not awaited)
            asyncio.ensure_future(braked).add_done_callback(_quiet)
    worker.halt(session, STOPPED)


def _quiet(future: asyncio.Future[str]) -> None:
    """A reply nobody awaits: read its outcome (asyncio logs one never read)."""
    if not future.cancelled():
        future.exception()


def waited_reply(pending: asyncio.Future[str], peer: str) -> str:
    """The line for a reply that waited: its text, its error, or ``SHUTTING_DOWN`` if it
    was cancelled (a bug is logged with ``peer`` and costs one error line)."""
    if pending.cancelled():
        return replies.SHUTTING_DOWN
    error = pending.exception()
    if isinstance(error, C2rvizError):
        return replies.error(error)
    if error is not None:
        log.error("internal error from %s", peer, exc_info=error)
        return replies.error("internal error (see the server log)")
    return pending.result()
