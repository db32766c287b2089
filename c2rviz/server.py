"""The TCP side: an asyncio line server in front of the shared world.

Each connection is an ``asyncio.Protocol``: it splits what arrives into lines,
runs every complete line through the parser and its ``Session``, and answers
all lines of one read (up to ``_BATCH_BYTES`` of them: a big read is run in
batches, one loop turn each) with one write. Nothing here knows kinematics or
drawing. The limits in ``config.Limits`` bound what one client can cost; a
client that breaks one is told why and closed, and no other client notices.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from itertools import chain

from . import replies
from .commands import USAGE, Bye, ForeignProtocol, Quit, Sleep, parse_line
from .config import Limits
from .errors import BadArguments, C2rvizError, LineError, LineTooLong
from .session import Session
from .world import World

__all__ = ["CommandServer", "Connection"]

log = logging.getLogger("c2rviz.server")

Line = str | C2rvizError  # a decoded line, or why it could not be one


class Connection(asyncio.Protocol):
    """One TCP client: its buffer, its session and its timers."""

    def __init__(self, server: CommandServer) -> None:
        self.server = server
        self.limits = server.limits
        self.session = Session(server.world)
        self.transport: asyncio.Transport | None = None
        self.peer = "?"
        self.buffer = b""
        self.backlog: list[Line] = []  # lines read but waiting behind a sleep
        self.wake_timer: asyncio.Handle | None = None  # set while reading is paused
        self.sleeping = False  # the pause is a `sleep`, which is answered when it ends
        self.partial_timer: asyncio.TimerHandle | None = None
        self.linger_timer: asyncio.TimerHandle | None = None
        self.closing = False
        self.eof = False
        self.closed = asyncio.get_running_loop().create_future()

    # asyncio callbacks

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        peer = transport.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        server = self.server
        server.open.add(self)
        if server.stopping:
            self._close_with(replies.SHUTTING_DOWN)
        elif len(server.connections) >= self.limits.max_clients:
            log.warning("refused %s: %d clients already", self.peer, len(server.connections))
            self._close_with(replies.too_many_clients(self.limits.max_clients))
        else:
            server.connections.add(self)
            server.world.set_client_count(len(server.connections))
            log.info("client %s connected", self.peer)

    def connection_lost(self, exc: Exception | None) -> None:
        self._cancel_timers()
        self.closing = True
        server = self.server
        server.open.discard(self)
        if self in server.connections:
            server.connections.discard(self)
            server.world.set_client_count(len(server.connections))
            log.info("client %s left", self.peer)
        if not self.closed.done():
            self.closed.set_result(None)

    def data_received(self, data: bytes) -> None:
        if self.closing:
            return
        buffer = self.buffer + data if self.buffer else data
        if self.wake_timer is not None:
            self.buffer = buffer  # reading is paused; the wake-up goes on from here
            return
        self._consume(buffer)

    def eof_received(self) -> bool:
        self.eof = True
        if self.closing:
            return False  # done lingering: asyncio closes the transport
        if self.wake_timer is None:
            self._close()
        return True  # keep the write side open until the replies are out

    # line handling

    def _consume(self, buffer: bytes) -> None:
        """Run the complete lines in ``buffer``, one batch of them; keep the rest."""
        cut = buffer.rfind(b"\n", 0, _BATCH_BYTES)
        if cut < 0:
            cut = buffer.find(b"\n")  # the first line is longer than a batch
        if cut >= 0:
            self.buffer = buffer[cut + 1 :]
            if self.partial_timer is not None:  # the line it timed is finished
                self.partial_timer.cancel()
                self.partial_timer = None
            self._run(self._decode(buffer[:cut]))
        else:
            self.buffer = buffer
        if self.closing or self.wake_timer is not None:
            return  # while paused we do not read, so an unfinished line is not the client's fault
        if b"\n" in self.buffer:  # more complete lines: let the other clients in first
            self._pause([], 0.0, sleeping=False)
        elif len(self.buffer) > self.limits.max_line:
            self._close_with(replies.error(LineTooLong(self.limits.max_line)))
        elif self.buffer and self.partial_timer is None:
            self.partial_timer = asyncio.get_running_loop().call_later(
                self.limits.partial_timeout_s, self._partial_timeout
            )

    def _decode(self, complete: bytes) -> list[Line]:
        """Split complete lines; mark the undecodable and the over-long ones."""
        max_line = self.limits.max_line
        if complete.isascii():  # the usual case: one decode and one split for the batch
            split = complete.decode("ascii").split("\n")
            if len(complete) <= max_line or max(map(len, split)) <= max_line:
                return split  # type: ignore[return-value]
        elif len(complete) <= max_line:
            try:
                return complete.decode().split("\n")  # type: ignore[return-value]
            except UnicodeDecodeError:
                pass
        lines: list[Line] = []
        for raw in complete.split(b"\n"):
            if len(raw) > max_line:
                lines.append(LineTooLong(max_line))
                break  # the connection closes here; nothing after it runs
            try:
                lines.append(raw.decode())
            except UnicodeDecodeError:
                lines.append(LineError(replies.NOT_UTF8))
        return lines

    def _run(self, lines: list[Line]) -> None:
        """Answer ``lines`` in order, stopping at a sleep, bye, quit or fatal line."""
        out: list[str] = []
        reply = out.append
        execute = self.session.execute
        note = self.server.world.note_command
        for i, line in enumerate(lines):
            try:
                if line.__class__ is not str:
                    raise line  # type: ignore[misc]
                command = parse_line(line)  # type: ignore[arg-type]
                if command is None:
                    continue
                note(line)  # type: ignore[arg-type]
                if command.__class__ in _CONNECTION_COMMANDS:
                    if isinstance(command, Sleep) and command.seconds > self.limits.max_sleep_s:
                        raise BadArguments(
                            "sleep",
                            f"{command.seconds:g} s is over the limit of "
                            f"{self.limits.max_sleep_s:g} s",
                            USAGE["sleep"],
                        )
                    self._write(out)
                    self._connection_command(command, lines[i + 1 :])
                    return
                reply(execute(command))
            except (ForeignProtocol, LineTooLong) as exc:
                out.append(replies.error(exc))
                self._write(out)
                self._close()
                return
            except C2rvizError as exc:
                reply(replies.error(exc))
            except Exception:  # a bug must cost one reply, never the server
                log.exception("internal error on %r from %s", line, self.peer)
                reply(replies.error("internal error (see the server log)"))
        self._write(out)

    def _connection_command(self, command: object, rest: list[Line]) -> None:
        if isinstance(command, Sleep):
            self._pause(rest, command.seconds, sleeping=True)
        elif isinstance(command, Bye):
            self._write([replies.BYE])
            self._close()
        elif isinstance(command, Quit):
            self._write([replies.OK])
            self._write([replies.SHUTTING_DOWN] * self._unanswered(rest))
            self.server.request_quit()  # before the close: a client seeing EOF sees it done
            self._close()

    def _pause(self, rest: list[Line], seconds: float, sleeping: bool) -> None:
        """Stop reading; after ``seconds`` (0: the next loop turn) run ``rest`` and go on."""
        self.backlog = rest
        self.sleeping = sleeping
        assert self.transport is not None
        self.transport.pause_reading()
        loop = asyncio.get_running_loop()
        if seconds > 0:
            self.wake_timer = loop.call_later(seconds, self._wake)
        else:
            self.wake_timer = loop.call_soon(self._wake)

    def _wake(self) -> None:
        self.wake_timer = None
        if self.closing:
            return
        if self.sleeping:
            self.sleeping = False
            self._write([replies.OK])
        backlog, self.backlog = self.backlog, []
        self._run(backlog)
        if self.closing or self.wake_timer is not None:
            return
        buffer, self.buffer = self.buffer, b""
        self._consume(buffer)
        if self.closing or self.wake_timer is not None:
            return
        if self.eof:
            self._close()
        elif self.transport is not None:
            self.transport.resume_reading()

    def _partial_timeout(self) -> None:
        self.partial_timer = None
        if self.buffer and not self.closing:
            self._close_with(replies.incomplete_line(self.limits.partial_timeout_s))

    # output and closing

    def _write(self, out: list[str]) -> None:
        if not out or self.closing or self.transport is None or self.transport.is_closing():
            return
        self.transport.write(("\n".join(out) + "\n").encode())
        unread = self.transport.get_write_buffer_size()
        if unread > self.limits.max_unread:
            log.warning("closing %s: %d bytes of replies unread", self.peer, unread)
            self.closing = True
            self.transport.abort()

    def _close_with(self, text: str) -> None:
        self._write([text])
        self._close()

    def _close(self) -> None:
        """Send what is queued, then close.

        A socket closed with input still unread sends RST, and RST throws away
        replies not yet delivered. So unless the client has finished sending, we
        half-close (FIN after the replies) and read and drop its input until it
        closes too, for at most ``_LINGER_S``.
        """
        self.closing = True
        self.buffer = b""
        self._cancel_timers()
        transport = self.transport
        if transport is None or transport.is_closing():
            return
        if self.eof:
            transport.close()  # nothing more will come: nothing to linger for
            return
        transport.write_eof()
        transport.resume_reading()
        self.linger_timer = asyncio.get_running_loop().call_later(_LINGER_S, transport.abort)

    def _cancel_timers(self) -> None:
        for timer in (self.wake_timer, self.partial_timer, self.linger_timer):
            if timer is not None:
                timer.cancel()
        self.wake_timer = self.partial_timer = self.linger_timer = None

    def shutdown(self) -> None:
        """The program is stopping: answer what was read, then close."""
        if self.closing:
            return
        self._write([replies.SHUTTING_DOWN] * (self.sleeping + self._unanswered(self.backlog)))
        self.backlog = []
        self._close()

    def _unanswered(self, rest: list[Line]) -> int:
        """How many of ``rest`` and the complete lines still buffered would get a reply."""
        cut = self.buffer.rfind(b"\n")
        buffered = self._decode(self.buffer[:cut]) if cut >= 0 else []
        return sum(map(_is_command, chain(rest, buffered)))


def _is_command(line: Line) -> bool:
    """True for a line that would get a reply (not blank, not only a comment)."""
    if line.__class__ is not str:
        return True
    try:
        return parse_line(line) is not None  # type: ignore[arg-type]
    except C2rvizError:
        return True


_CONNECTION_COMMANDS = frozenset({Sleep, Bye, Quit})
_BATCH_BYTES = 8192  # complete lines run per client per loop turn: at most ~20 ms of work
_LINGER_S = 2.0  # after the last reply, how long a closing client's input is read and dropped


class CommandServer:
    """Listens for TCP clients and runs each one's lines against one ``World``."""

    def __init__(
        self,
        world: World,
        limits: Limits | None = None,
        on_quit: Callable[[], None] | None = None,
    ) -> None:
        """Set up the server; ``start`` makes it listen.

        Args:
            world: The shared state every client acts on.
            limits: What one client may cost.
            on_quit: Called once when a client sends ``quit``.
        """
        self.world = world
        self.limits = limits if limits is not None else Limits()
        self.on_quit = on_quit
        self.connections: set[Connection] = set()  # the clients being served
        self.open: set[Connection] = set()  # those and the refused ones, until their socket closes
        self.stopping = False
        self.quit_requested = False
        self._server: asyncio.Server | None = None

    async def start(self, host: str = "127.0.0.1", port: int = 0) -> tuple[str, int]:
        """Start listening; return the address actually bound (port 0 picks one)."""
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(lambda: Connection(self), host, port)
        bound = self._server.sockets[0].getsockname()
        return bound[0], bound[1]

    def request_quit(self) -> None:
        if not self.quit_requested:
            self.quit_requested = True
            log.info("quit requested by a client")
            if self.on_quit is not None:
                self.on_quit()

    async def stop(self, grace_s: float = 1.0) -> None:
        """Stop accepting, answer and close every client, free the port."""
        self.stopping = True
        if self._server is not None:
            self._server.close()
        for connection in list(self.connections):
            connection.shutdown()
        if self.open:  # each gets its last replies and then closes, or is cut off
            await asyncio.wait([c.closed for c in self.open], timeout=grace_s)
        left = list(self.open)
        for connection in left:
            if connection.transport is not None:
                connection.transport.abort()
        if left:  # let connection_lost run, so every socket is closed when we return
            await asyncio.wait([c.closed for c in left], timeout=1.0)
        if self._server is not None:
            await self._server.wait_closed()
