"""The ``watch`` stream from a client (``state`` and ``event`` lines on a connection of its
own), and how a client shows the server's text to a person.

A watching connection receives stream lines between its replies, so a client that
also sends commands would have to sort them apart; ``Client.watch`` and the REPL's
``watch`` open a second connection instead (same server, robot and units), ask
``watch [HZ]`` there and read nothing but the stream. ``WatchStream`` reads it
line by line through the protocol's ``LineFramer`` (so a runaway line cannot grow
memory) and gives each line as text (``lines``) or as a ``State``/``Event`` record
(iterating).

From the command line, ``watch_lines`` opens such a connection (``WatchStream``), asks
``watch [HZ]`` and yields the stream's lines; ``watch_main`` is ``c2rviz-cli --watch``,
and the REPL's local ``watch`` prints the same lines until Ctrl-C.

A reply is shown to a person by the REPL and the player; one that carries terminal
escape sequences (``\x1b[2J``, a title change, bidirectional overrides) must not
act on their terminal. ``shown`` writes every character ``str.isprintable`` refuses
(C0/C1 controls, DEL, format characters such as U+202E, separators) as a Python
escape (``\x1b``, ``\u202e``); tabs and ordinary text pass as they are. ``Progress`` is
how ``c2rviz-play`` (and the REPL's ``file``) shows each played line and its reply (the
server's text escaped by ``shown``); the stream's lines are printed escaped too.
"""

from __future__ import annotations

import contextlib
import shutil
import socket
import sys
from collections import deque
from collections.abc import Iterator
from typing import TextIO

from ..errors import C2rvizError, LineTooLong
from ..protocol.framing import Line, LineFramer
from ..protocol.grammar import parse_line
from ..protocol.verbs.scene import Watch
from .connection import ServerUnavailable
from .errors import CommandError, ConnectionLost, ReplyTooLong, UnexpectedReply
from .records import Event, State, read_stream_line


def line_text(line: Line, asked: str, max_line: int) -> str:
    """A framed stream line as text, without a trailing CR.

    Raises:
        ReplyTooLong: the line was longer than ``max_line`` bytes.
        UnexpectedReply: it is not UTF-8 text.
    """
    if isinstance(line, LineTooLong):
        raise ReplyTooLong(asked, max_line)
    if not isinstance(line, str):
        raise UnexpectedReply(asked, "", "a line that is not UTF-8 text")
    return line.removesuffix("\r")


def watch_request(hz: float | None, degrees: bool, robot: str | None) -> list[str]:
    """The lines that set up a watching connection like the client's own."""
    asked = [f"robot {robot}"] if robot is not None else []
    if degrees:
        asked.append("degrees")
    asked.append("watch" if hz is None else f"watch {hz!r}")
    return asked


class WatchStream:
    """A connection that asked ``watch``: iterate for records, ``lines()`` for the text.

    A context manager; ``close()`` ends the stream (the connection closes).

    Attributes:
        host, port: The server.
    """

    def __init__(
        self,
        host: str,
        port: int,
        hz: float | None = None,
        *,
        degrees: bool = False,
        robot: str | None = None,
        max_line: int = 1 << 20,
        timeout: float | None = None,
    ) -> None:
        """Connect and ask for the stream.

        Args:
            host, port: The command server.
            hz: Most ``state`` lines a second (None: the server's frame rate).
            degrees: Values in degrees.
            robot: Watch this robot of a cell (None: the port's own).
            max_line: Longest line [bytes]; past it the stream closes.
            timeout: Longest wait for a line [s] (None: no limit).

        Raises:
            ServerUnavailable: no server at ``host:port``.
            CommandError: the server refused a line of the request (a bad robot, HZ).
        """
        self.host = host
        self.port = port
        try:
            self._sock = socket.create_connection((host, port), timeout=5.0)
        except OSError as exc:
            raise ServerUnavailable(host, port, 0.0, exc.strerror or str(exc)) from None
        self._sock.settimeout(timeout)
        self._framer = LineFramer(max_line)
        self._lines: deque[Line] = deque()
        self._held: deque[str] = deque()  # stream lines that came before a reply
        try:
            asked = watch_request(hz, degrees, robot)
            self._sock.sendall("".join(f"{line}\n" for line in asked).encode())
            for line in asked:
                reply = self._reply(line)
                if not reply.startswith("ok"):
                    raise CommandError(line, reply)
        except BaseException:
            self.close()
            raise

    def _reply(self, line: str) -> str:
        """The reply to ``line`` (stream lines before it are kept for later)."""
        while True:
            text = self._next(line)
            if text is None:
                raise ConnectionLost(self.host, self.port, line)
            if read_stream_line(text) is None:
                return text
            self._held.append(text)

    def _next(self, asked: str) -> str | None:
        """The next line (None: the server closed the connection)."""
        while not self._lines:
            batch = self._framer.take()
            if batch is not None:
                self._lines.extend(batch)
                break
            if self._framer.too_long:
                raise ReplyTooLong(asked, self._framer.max_line)
            try:
                chunk = self._sock.recv(65536)
            except OSError:
                chunk = b""
            if not chunk:
                return None
            self._framer.feed(chunk)
        return line_text(self._lines.popleft(), asked, self._framer.max_line)

    def lines(self) -> Iterator[str]:
        """Each stream line as text, until the server closes the connection."""
        while self._held:
            yield self._held.popleft()
        while (line := self._next("watch")) is not None:
            yield line

    def __iter__(self) -> Iterator[State | Event]:
        """Each stream line as a record (other lines, if any, are skipped)."""
        for line in self.lines():
            record = read_stream_line(line)
            if record is not None:
                yield record

    def send(self, line: str) -> None:
        """Send a command on the watching connection (its reply comes among the stream's
        lines: everything the stream wrote before it comes first)."""
        self._sock.sendall(line.encode() + b"\n")

    def close(self) -> None:
        with contextlib.suppress(OSError):  # wakes a thread blocked reading it
            self._sock.shutdown(socket.SHUT_RDWR)
        self._sock.close()

    def __enter__(self) -> WatchStream:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def watch_lines(
    host: str, port: int, hz: float | None, degrees: bool, robot: str | None = None
) -> Iterator[str]:
    """The ``state`` and ``event`` lines of a new connection that asked ``watch [HZ]``
    (in degrees if ``degrees``; of ``robot`` of a cell if given), until the server closes it.

    Raises:
        ServerUnavailable: no server at ``host:port``.
        C2rvizError: the server refused ``watch`` (its ``error:`` reply).
    """
    with WatchStream(host, port, hz, degrees=degrees, robot=robot) as stream:
        yield from stream.lines()


def watch_main(host: str, port: int, hz: str, out: TextIO) -> int:
    """``c2rviz-cli --watch [HZ]``: print the stream until Ctrl-C (status 0) or until the
    server goes (status 1)."""
    try:
        command = parse_line(f"watch {hz}")
        assert isinstance(command, Watch)
        for line in watch_lines(host, port, command.hz, False):
            print(shown(line), file=out, flush=True)
    except KeyboardInterrupt:
        return 0
    except C2rvizError as exc:
        print(f"c2rviz-cli: {shown(str(exc))}", file=sys.stderr)
        return 1 if isinstance(exc, (ServerUnavailable, ConnectionError)) else 2
    except BrokenPipeError:  # the reader of our output left
        return 0
    print(f"c2rviz-cli: connection to {host}:{port} closed by the server", file=sys.stderr)
    return 1


def _escape(char: str) -> str:
    code = ord(char)
    if code < 0x100:
        return f"\\x{code:02x}"
    if code < 0x10000:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def shown(text: str) -> str:
    """``text`` with every control or format character written as its escape."""
    if text.isprintable():
        return text
    return "".join(char if char.isprintable() or char == "\t" else _escape(char) for char in text)


class Progress:
    """Shows each played line and its reply.

    On a terminal (``in_place``) one status line is rewritten in place; replies
    that carry data and every error stay on screen. Otherwise one plain line
    per command. ``quiet``: errors alone (``c2rviz-play --quiet``).
    """

    def __init__(
        self, out: TextIO, err: TextIO, in_place: bool | None = None, *, quiet: bool = False
    ) -> None:
        self.out = out
        self.err = err
        self.quiet = quiet
        self.in_place = out.isatty() if in_place is None else in_place
        self._dirty = False

    def step(self, label: str, text: str, reply: str) -> None:
        if self.quiet:
            return
        message = f"{label} {text} -> {shown(reply)}"
        if not self.in_place:
            print(message, file=self.out, flush=True)
            return
        keep = reply not in ("ok", "ok bye") and not reply.startswith("error")
        fitted = message if keep else self._fit(message)
        self.out.write("\r\x1b[K" + fitted + ("\n" if keep else ""))
        self.out.flush()
        self._dirty = not keep

    def waiting(self, label: str, text: str, note: str) -> None:
        """On a terminal, show that ``text``'s reply is awaited (``-> moving``); the
        ``step`` that follows overwrites it. Elsewhere nothing: one line per command."""
        if not self.in_place or self.quiet:
            return
        self.out.write("\r\x1b[K" + self._fit(f"{label} {text} -> {note}"))
        self.out.flush()
        self._dirty = True

    def error(self, message: str) -> None:
        self.end_line()
        print(shown(message), file=self.err, flush=True)

    def end_line(self) -> None:
        """Finish the in-place line so the next output starts on its own line."""
        if self._dirty:
            self.out.write("\n")
            self.out.flush()
            self._dirty = False

    @staticmethod
    def _fit(message: str) -> str:
        """``message`` cut to the terminal's width, so rewriting it in place works."""
        width = shutil.get_terminal_size().columns - 1
        return message if len(message) <= width else message[: width - 3] + "..."
