"""The asyncio side of the wire: ``AsyncLineClient`` (one connection, a line out and its
reply back) and ``AsyncWatchStream`` (a connection of its own that reads the ``watch``
stream), for ``AsyncClient``.

As ``lines.LineClient``: replies are read through the protocol's ``LineFramer`` (a reply
over ``max_reply`` bytes closes the connection), the unit mode and the robot are
remembered and restored when a lost connection is opened again, and the same errors
say what went wrong. Calls on one client are taken in turn (a lock): a reply that waits
(an arrival, a ``sleep``) holds the calls behind it, as the server holds the lines.
"""

from __future__ import annotations

import asyncio
import contextlib
import socket
import time
from collections import deque
from collections.abc import AsyncIterator

from ..protocol.framing import Line, LineFramer
from ..protocol.verbs.arm import RobotChoice
from ..protocol.verbs.seed import Units
from .connection import MAX_REPLY_BYTES, LineState, ServerUnavailable
from .errors import CommandError, ConnectionLost, ReplyTimeout, ReplyTooLong
from .records import Event, State, read_stream_line
from .stream import line_text, watch_request

Streams = tuple[asyncio.StreamReader, asyncio.StreamWriter]


async def open_stream(host: str, port: int, retry_s: float) -> Streams:
    """A connection to ``host:port``, retrying a refused one (0.05 s doubling to 1 s) for
    up to ``retry_s`` [s].

    Raises:
        ServerUnavailable: nothing accepted it in time, or the host does not resolve.
    """
    start = time.monotonic()
    delay = 0.05
    while True:
        try:
            return await asyncio.wait_for(asyncio.open_connection(host, port), 5.0)
        except socket.gaierror as exc:
            raise ServerUnavailable(host, port, 0.0, exc.strerror or str(exc)) from None
        except (OSError, asyncio.TimeoutError) as exc:
            left = start + retry_s - time.monotonic()
            if left <= 0:
                why = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
                raise ServerUnavailable(host, port, time.monotonic() - start, why) from None
            await asyncio.sleep(min(delay, left))
            delay = min(delay * 2, 1.0)


class _LineReader:
    """Lines from a stream reader, through a ``LineFramer``."""

    def __init__(self, reader: asyncio.StreamReader, max_line: int) -> None:
        self.reader = reader
        self.framer = LineFramer(max_line)
        self.lines: deque[Line] = deque()

    async def next(self, asked: str) -> str | None:
        """The next line (None: the server closed first).

        Raises:
            ReplyTooLong, UnexpectedReply (not UTF-8).
        """
        while not self.lines:
            batch = self.framer.take()
            if batch is not None:
                self.lines.extend(batch)
                break
            if self.framer.too_long:
                raise ReplyTooLong(asked, self.framer.max_line)
            try:
                chunk = await self.reader.read(65536)
            except (ConnectionError, OSError):
                chunk = b""
            if not chunk:
                return None
            self.framer.feed(chunk)
        return line_text(self.lines.popleft(), asked, self.framer.max_line)


class AsyncLineClient(LineState):
    """One asyncio connection to the command server (see the module docstring, and
    ``LineState`` for what it remembers)."""

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 31000,
        *,
        timeout: float | None = None,
        retry_s: float = 10.0,
        degrees: bool = False,
        robot: str | None = None,
        max_reply: int = MAX_REPLY_BYTES,
    ) -> None:
        """Args as ``Client``'s."""
        super().__init__(
            host,
            port,
            timeout=timeout,
            retry_s=retry_s,
            degrees=degrees,
            robot=robot,
            max_reply=max_reply,
        )
        self._streams: Streams | None = None
        self._reader: _LineReader | None = None
        self._lock = asyncio.Lock()

    @property
    def is_open(self) -> bool:
        return self._streams is not None

    async def open(self) -> None:
        """Connect; restore the unit mode and robot (see ``LineClient.open``)."""
        async with self._lock:
            await self._open()

    async def _open(self) -> None:
        if self._streams is not None:
            return
        self._streams = await open_stream(self.host, self.port, self.retry_s)
        self._reader = _LineReader(self._streams[0], self.max_reply)
        self._names = None
        if self.chosen_robot is not None:
            line = f"robot {self.chosen_robot}"
            reply = await self._exchange(line, RobotChoice(self.chosen_robot))
            refused = self._robot_refused(line, reply)
            if refused is not None:
                await self._close()
                raise refused
        self._insist = False
        if self._degrees:
            await self._exchange("degrees", Units(degrees=True))

    async def close(self) -> None:
        """Close the connection (a later call reconnects)."""
        await self._close()

    async def _close(self) -> None:
        streams, self._streams = self._streams, None
        self._reader = None
        if streams is not None:
            streams[1].close()
            with contextlib.suppress(ConnectionError, OSError):
                await streams[1].wait_closed()

    async def __aenter__(self) -> AsyncLineClient:
        await self.open()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    async def ask(self, line: str, tracked: object = None) -> str:
        """Send ``line`` (one command) and return its reply as it came."""
        async with self._lock:
            await self._open()
            return await self._exchange(line.strip(), tracked)

    async def _exchange(self, line: str, tracked: object) -> str:
        assert self._streams is not None and self._reader is not None
        writer = self._streams[1]
        try:
            writer.write(line.encode() + b"\n")
            await writer.drain()
            if self.timeout is None:
                reply = await self._reply(line)
            else:
                reply = await asyncio.wait_for(self._reply(line), self.timeout)
        except asyncio.TimeoutError:
            await self._close()
            raise ReplyTimeout(line, self.timeout or 0.0) from None
        except (ConnectionError, OSError):
            reply = None
        except BaseException:  # cancelled, too long: the stream is out of step
            await self._close()
            raise
        if reply is None:
            await self._close()
            raise ConnectionLost(self.host, self.port, line)
        self._remember(reply, tracked)
        return reply

    async def _reply(self, line: str) -> str | None:
        """The next line that is not a ``watch`` stream's (see ``LineClient``)."""
        assert self._reader is not None
        while True:
            reply = await self._reader.next(line)
            if reply is None or not reply.startswith(("state ", "event ")):
                return reply

    async def joint_names(self) -> tuple[str, ...]:
        """The chain's joint names, in index order (asked once per connection and robot)."""
        if self._names is None or not self.is_open:
            return self._take_names(await self.ask("names"))
        return self._names


class AsyncWatchStream:
    """The ``watch`` stream on a connection of its own: ``async for record in stream``;
    ``lines()`` for the text. An async context manager; ``close()`` ends it."""

    def __init__(
        self,
        host: str,
        port: int,
        hz: float | None = None,
        *,
        degrees: bool = False,
        robot: str | None = None,
        max_line: int = MAX_REPLY_BYTES,
    ) -> None:
        """Nothing happens until it is entered or iterated (``start``)."""
        self.host = host
        self.port = port
        self._asked = watch_request(hz, degrees, robot)
        self._max_line = max_line
        self._streams: Streams | None = None
        self._reader: _LineReader | None = None
        self._held: deque[str] = deque()

    async def start(self) -> None:
        """Connect and ask for the stream (once).

        Raises:
            ServerUnavailable, CommandError (the server refused a line of the request).
        """
        if self._streams is not None:
            return
        self._streams = await open_stream(self.host, self.port, 0.0)
        self._reader = _LineReader(self._streams[0], self._max_line)
        self._streams[1].write("".join(f"{line}\n" for line in self._asked).encode())
        try:
            for line in self._asked:
                while True:
                    text = await self._reader.next(line)
                    if text is None:
                        raise ConnectionLost(self.host, self.port, line)
                    if read_stream_line(text) is None:
                        break
                    self._held.append(text)
                if not text.startswith("ok"):
                    raise CommandError(line, text)
        except BaseException:
            await self.close()
            raise

    async def lines(self) -> AsyncIterator[str]:
        """Each stream line as text, until the server closes the connection."""
        await self.start()
        while self._held:
            yield self._held.popleft()
        assert self._reader is not None
        while (line := await self._reader.next("watch")) is not None:
            yield line

    async def __aiter__(self) -> AsyncIterator[State | Event]:
        async for line in self.lines():
            record = read_stream_line(line)
            if record is not None:
                yield record

    async def close(self) -> None:
        streams, self._streams = self._streams, None
        if streams is not None:
            streams[1].close()
            with contextlib.suppress(ConnectionError, OSError):
                await streams[1].wait_closed()

    async def __aenter__(self) -> AsyncWatchStream:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()
