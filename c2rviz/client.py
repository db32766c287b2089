"""The controller side of the wire, shared by the REPL and the player.

A ``Client`` is one TCP connection to the command server: it connects with
retries (the server may not be up yet, or may be restarting), sends one line
and reads its one reply, and remembers the connection's unit mode so that it
can be restored after a reconnect. It imports the parser and the settings
reader only: never Pinocchio or viser, so the clients start in a blink.
Where the server is (flags, ini) and where command files are found is in
``client_options``, re-exported here.
"""

from __future__ import annotations

import select
import socket
import time
from collections import deque
from collections.abc import Callable
from typing import BinaryIO

from .client_options import (
    COMMANDS_DIR,
    add_connection_args,
    default_address,
    find_script,
    server_address,
)
from .commands import Units, Where, parse_line
from .errors import C2rvizError

__all__ = [
    "COMMANDS_DIR",
    "Client",
    "ConnectionLost",
    "ServerUnavailable",
    "add_connection_args",
    "default_address",
    "find_script",
    "server_address",
]

_FIRST_DELAY_S = 0.05
_MAX_DELAY_S = 1.0


class ServerUnavailable(C2rvizError):
    """No server answered at ``host:port`` within the retry time."""

    def __init__(self, host: str, port: int, waited_s: float, reason: str) -> None:
        self.host = host
        self.port = port
        self.waited_s = waited_s
        self.reason = reason
        super().__init__(
            f"no c2rviz server at {host}:{port} after {waited_s:.1f} s ({reason}); "
            "start one with `c2rviz`, or give --host/--port"
        )


class ConnectionLost(C2rvizError):
    """The server closed the connection (it stopped, restarted or dropped us)."""

    def __init__(self, host: str, port: int) -> None:
        self.host = host
        self.port = port
        super().__init__(f"connection to {host}:{port} lost (the server stopped or restarted)")


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


class Client:
    """One connection to the command server: a line out, a reply line back, in order.

    The connection opens lazily (``open`` or the first ``send``). Replies are
    matched to lines by order, so several lines may be sent before their
    replies are read (pipelining). An interrupted read or write leaves the
    stream out of step, so the connection is closed; the next ``send``
    reconnects and restores the unit mode.

    Attributes:
        degrees: The connection's angle unit as last confirmed by the server.
        robot, joint_names: From ``names``, once ``joint_names()`` has asked.
    """

    def __init__(
        self,
        host: str,
        port: int,
        *,
        retry_s: float = 10.0,
        notify: Callable[[str], None] | None = None,
    ) -> None:
        """Args:
        host, port: The command server.
        retry_s: How long to keep retrying a refused connection [s].
        notify: Called with a short message when retrying begins.
        """
        self.host = host
        self.port = port
        self.retry_s = retry_s
        self.notify = notify
        self.degrees = False
        self.robot: str | None = None
        self._names: tuple[str, ...] | None = None
        self._sock: socket.socket | None = None
        self._reader: BinaryIO | None = None
        self._sent: deque[Units | None] = deque()  # one per reply still to read

    @property
    def is_open(self) -> bool:
        return self._sock is not None

    @property
    def pending(self) -> int:
        """Lines sent whose replies have not been read yet."""
        return len(self._sent)

    def open(self) -> None:
        """Connect (retrying with backoff up to ``retry_s``) and restore the unit mode.

        Raises:
            ServerUnavailable: nothing accepted the connection in time.
        """
        if self._sock is not None:
            return
        start = time.monotonic()
        deadline = start + self.retry_s
        delay = _FIRST_DELAY_S
        told = False
        while True:
            try:
                sock = socket.create_connection((self.host, self.port), timeout=5.0)
                break
            except socket.gaierror as exc:  # a bad host name does not get better
                raise ServerUnavailable(self.host, self.port, 0.0, _reason(exc)) from None
            except OSError as exc:
                left = deadline - time.monotonic()
                if left <= 0:
                    waited = time.monotonic() - start
                    raise ServerUnavailable(self.host, self.port, waited, _reason(exc)) from None
                if not told and self.notify is not None:
                    self.notify(
                        f"no server at {self.host}:{self.port} yet ({_reason(exc)}); "
                        f"retrying for up to {self.retry_s:g} s"
                    )
                    told = True
                time.sleep(min(delay, left))
                delay = min(delay * 2, _MAX_DELAY_S)
        sock.settimeout(None)  # a reply may follow a long server-side sleep
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._sock = sock
        self._reader = sock.makefile("rb")
        self._sent.clear()
        self._names = None
        if self.degrees:
            reply = self.ask("degrees")
            if not reply.startswith("ok"):  # pragma: no cover - the server always accepts it
                self.degrees = False

    def alive(self) -> bool:
        """False when the server has closed this idle connection (the socket reads EOF).

        Checks without blocking; a closed connection is closed here too, so the
        next ``send`` reconnects. Only meaningful with no replies pending.
        """
        sock = self._sock
        if sock is None or self._sent:
            return sock is not None
        try:
            readable, _, _ = select.select([sock], [], [], 0)
            if not readable or sock.recv(1, socket.MSG_PEEK):
                return True
        except OSError:
            pass
        self.close()
        return False

    def close(self) -> None:
        """Close the connection (a later ``send`` reconnects)."""
        sock, self._sock = self._sock, None
        self._sent.clear()
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        if sock is not None:
            sock.close()

    def send(self, line: str) -> bool:
        """Send one command line; return False (sending nothing) for a blank/comment line.

        Raises:
            ConnectionLost: the server is gone.
            ServerUnavailable: reconnecting failed.
        """
        try:
            command = parse_line(line)
        except C2rvizError:
            command = Where()  # the server will answer with an error: one reply all the same
        if command is None:
            return False
        self.open()
        assert self._sock is not None
        try:
            self._sock.sendall(line.rstrip("\r\n").encode() + b"\n")
        except OSError:
            self.close()
            raise ConnectionLost(self.host, self.port) from None
        except BaseException:  # interrupted mid-line: the stream is out of step
            self.close()
            raise
        self._sent.append(command if isinstance(command, Units) else None)
        return True

    def read_reply(self) -> str:
        """The reply to the oldest unanswered line, without its newline.

        Raises:
            ConnectionLost: the server closed the connection first.
        """
        if not self._sent or self._reader is None:
            raise RuntimeError("read_reply() with no line waiting for its reply")
        try:
            raw = self._reader.readline()
        except OSError:
            raw = b""
        except BaseException:  # Ctrl-C while waiting: the reply would arrive late
            self.close()
            raise
        if not raw.endswith(b"\n"):
            self.close()
            raise ConnectionLost(self.host, self.port)
        units = self._sent.popleft()
        reply = raw.decode("utf-8", "replace").rstrip("\r\n")
        if units is not None and reply.startswith("ok"):
            self.degrees = units.degrees
        return reply

    def ask(self, line: str) -> str:
        """Send ``line`` and return its reply (every earlier reply must have been read)."""
        if self.pending:
            raise RuntimeError(f"ask() with {self.pending} replies unread")
        if not self.send(line):
            raise ValueError(f"{line!r} is not a command: the server would not answer")
        return self.read_reply()

    def joint_names(self) -> tuple[str, ...]:
        """The chain's joint names, in index order (asked once per connection).

        Raises:
            C2rvizError: the server answered ``names`` with an error.
        """
        self.open()
        if self._names is None:
            reply = self.ask("names")
            robot, _, names = reply[3:].rpartition(" ")
            if not reply.startswith("ok ") or not robot:
                raise C2rvizError(f"unexpected reply to 'names': {reply!r}")
            self.robot = robot
            self._names = tuple(names.split(","))
        return self._names

    def limits(self) -> list[tuple[float, float, str]]:
        """Each chain joint's (lower, upper, unit), in the connection's units."""
        reply = self.ask("limits")
        try:
            if not reply.startswith("ok "):
                raise ValueError(reply)
            out = []
            for item in reply[3:].split(","):
                span, unit = item.split(" ")
                lower, upper = span.split("..")
                out.append((float(lower), float(upper), unit))
            return out
        except ValueError:
            raise C2rvizError(f"unexpected reply to 'limits': {reply!r}") from None

    def where(self) -> list[float]:
        """The joint values in the connection's units."""
        reply = self.ask("where")
        if not reply.startswith("ok "):
            raise C2rvizError(f"unexpected reply to 'where': {reply!r}")
        return [float(v) for v in reply[3:].split(",")]
