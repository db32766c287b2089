"""One TCP connection to the command server: a line out, a reply line back, in order.

``LineClient`` is the wire under ``Client`` (and so under the REPL and the player):
it connects with retries (``connection.dial``: the server may not be up yet, or may be
restarting), sends lines and reads their replies through the protocol's own
``LineFramer`` (a reply longer than ``max_reply`` closes the connection: a server
that streams without newlines cannot grow the client's memory), and remembers the
connection's unit mode and chosen robot so that they are restored after a
reconnect. It imports the parser alone: never Pinocchio or viser.
"""

from __future__ import annotations

import select
import socket
from collections import deque
from collections.abc import Callable

from ..errors import C2rvizError, LineTooLong
from ..protocol.framing import Line, LineFramer
from ..protocol.grammar import parse_line
from .connection import MAX_REPLY_BYTES, LineState, dial
from .errors import ConnectionLost, ReplyTimeout, ReplyTooLong, UnexpectedReply

_CHUNK = 65536
_STREAM = ("state ", "event ")  # a watch stream's lines, which no reply starts with


class LineClient(LineState):
    """One connection; see the module docstring (and ``LineState`` for what it remembers).

    The connection opens lazily (``open``, or the first line sent). Replies are
    matched to lines by order, so several lines may be sent (``post``) before
    their replies are read (``read_reply``): pipelining. An interrupted read or
    write leaves the stream out of step, so the connection is closed; the next
    line reconnects and restores the unit mode and the robot chosen.
    """

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
        notify: Callable[[str], None] | None = None,
    ) -> None:
        """Args as ``LineState``'s, and ``notify``: called with a short message when
        retrying to connect begins."""
        super().__init__(
            host,
            port,
            timeout=timeout,
            retry_s=retry_s,
            degrees=degrees,
            robot=robot,
            max_reply=max_reply,
        )
        self.notify = notify
        self._sock: socket.socket | None = None
        self._framer = LineFramer(max_reply)
        self._lines: deque[Line] = deque()  # framed, not yet read
        self._sent: deque[tuple[str, object]] = deque()  # (line, tracked command) per reply due

    @property
    def is_open(self) -> bool:
        return self._sock is not None

    @property
    def pending(self) -> int:
        """Lines sent whose replies have not been read yet."""
        return len(self._sent)

    def open(self) -> None:
        """Connect (retrying with backoff up to ``retry_s``); restore the unit mode and robot.

        Raises:
            ServerUnavailable: nothing accepted the connection in time.
            CommandError: the robot asked for at construction is not the server's.
        """
        if self._sock is not None:
            return
        self._sock = dial(self.host, self.port, self.retry_s, self.notify)
        self._sock.settimeout(self.timeout)
        self._framer.clear()
        self._lines.clear()
        self._sent.clear()
        self._names = None
        if self.chosen_robot is not None:
            line = f"robot {self.chosen_robot}"
            refused = self._robot_refused(line, self.ask(line))
            if refused is not None:
                self.close()
                raise refused
        self._insist = False
        if self._degrees:
            reply = self.ask("degrees")
            if not reply.startswith("ok"):  # pragma: no cover - the server always accepts it
                self._degrees = False

    def alive(self) -> bool:
        """False when the server has closed this idle connection (the socket reads EOF).

        Checks without blocking; a closed connection is closed here too, so the
        next line reconnects. Only meaningful with no replies pending.
        """
        sock = self._sock
        if sock is None or self._sent:
            return sock is not None
        try:
            readable, _, _ = select.select([sock], [], [], 0)
            if not readable or self._lines or sock.recv(1, socket.MSG_PEEK):
                return True
        except OSError:
            pass
        self.close()
        return False

    def close(self) -> None:
        """Close the connection (a later line reconnects)."""
        sock, self._sock = self._sock, None
        self._sent.clear()
        self._lines.clear()
        self._framer.clear()
        if sock is not None:
            sock.close()

    def __enter__(self) -> LineClient:
        self.open()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def post(self, line: str) -> bool:
        """Send one command line without waiting for its reply (``read_reply`` reads it);
        False (sending nothing) for a blank or comment line.

        Raises:
            ConnectionLost: the server is gone.
            ServerUnavailable: reconnecting failed.
        """
        try:
            command = parse_line(line)
        except C2rvizError:
            command = False  # the server will answer with an error: one reply all the same
        if command is None:
            return False
        self._post(line.rstrip("\r\n"), command)
        return True

    def _post(self, line: str, tracked: object, data: bytes | None = None) -> None:
        """Send ``line`` (one command, no newline; ``data``: it encoded, with its newline),
        remembering ``tracked`` for its reply."""
        if self._sock is None:
            self.open()
        assert self._sock is not None
        try:
            self._sock.sendall(data or line.encode() + b"\n")
        except OSError:
            self.close()
            raise ConnectionLost(self.host, self.port, line) from None
        except BaseException:  # interrupted mid-line: the stream is out of step
            self.close()
            raise
        self._sent.append((line, tracked))

    def read_reply(self, *, interruptible: bool = False) -> str:
        """The reply to the oldest unanswered line, without its newline.

        Args:
            interruptible: Ctrl-C while waiting leaves the connection open and the
                reply still due (the caller reads it later, e.g. after sending
                ``stop`` on another connection). By default the connection is
                closed, since the reply would otherwise arrive late.

        Raises:
            ConnectionLost: the server closed the connection first.
            ReplyTooLong: the reply is longer than ``max_reply`` (the connection is closed).
            ReplyTimeout: no reply within ``timeout`` (the connection is closed).
            UnexpectedReply: the reply is not UTF-8 text.
        """
        if not self._sent or self._sock is None:
            raise RuntimeError("read_reply() with no line waiting for its reply")
        line, tracked = self._sent[0]
        try:
            raw = self._read_line()
            while isinstance(raw, str) and raw.startswith(_STREAM):  # `watch` on this connection
                raw = self._read_line()
        except TimeoutError:
            self.close()
            raise ReplyTimeout(line, self.timeout or 0.0) from None
        except OSError:
            raw = None
        except BaseException:  # Ctrl-C while waiting: what arrived stays buffered
            if not interruptible:
                self.close()
            raise
        if raw is None:
            self.close()
            raise ConnectionLost(self.host, self.port, line)
        if isinstance(raw, LineTooLong):
            self.close()
            raise ReplyTooLong(line, self.max_reply)
        self._sent.popleft()
        if not isinstance(raw, str):
            raise UnexpectedReply(line, "", "a line that is not UTF-8 text")
        reply = raw.removesuffix("\r")
        self._remember(reply, tracked)
        return reply

    def _read_line(self) -> Line | None:
        """The next line from the server (None: it closed first). An interrupted wait
        loses nothing: what has arrived stays in the framer."""
        lines = self._lines
        framer = self._framer
        if not lines and not framer.buffer:  # the usual case: a reply is one chunk
            assert self._sock is not None
            chunk = self._sock.recv(_CHUNK)
            if not chunk:
                return None
            if (
                chunk[-1:] == b"\n"
                and chunk.count(b"\n") == 1
                and len(chunk) <= self.max_reply
                and chunk.isascii()
            ):
                return chunk[:-1].decode("ascii")  # as the framer would: one line, in bounds
            framer.feed(chunk)
        while not lines:
            batch = framer.take()
            if batch is not None:
                lines.extend(batch)
                break
            if framer.too_long:
                return LineTooLong(self.max_reply)
            assert self._sock is not None
            chunk = self._sock.recv(_CHUNK)
            if not chunk:
                return None
            framer.feed(chunk)
        return lines.popleft()

    def ask(self, line: str) -> str:
        """Send ``line`` and return its reply as it came (``ok ...`` or ``error: ...``);
        every earlier reply must have been read."""
        if self._sent:
            raise RuntimeError(f"ask() with {len(self._sent)} replies unread")
        if not self.post(line):
            raise ValueError(f"{line!r} is not a command: the server would not answer")
        return self.read_reply()

    def joint_names(self) -> tuple[str, ...]:
        """The chain's joint names, in index order (asked once per connection and robot).

        Raises:
            UnexpectedReply: the reply to ``names`` is not a c2rviz one.
            CommandError: the server refused ``names``.
        """
        self.open()
        if self._names is None:
            return self._take_names(self.ask("names"))
        return self._names
