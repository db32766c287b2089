"""The controller side of the wire, shared by the REPL and the player.

A ``Client`` is one TCP connection to the command server: it connects with
retries (``dial``: the server may not be up yet, or may be restarting), sends
one line and reads its one reply, and remembers the connection's unit mode and
chosen robot so that they are restored after a reconnect. It imports the parser and the settings
reader only: never Pinocchio or viser, so the clients start in a blink.
Where the server is (flags, ini) and where command files are found is in
``client_options``, re-exported here.
"""

from __future__ import annotations

import select
import socket
from collections import deque
from collections.abc import Callable

from ..errors import C2rvizError
from ..protocol.grammar import parse_line
from ..protocol.verbs.cell import RobotChoice
from ..protocol.verbs.joints import Units
from ..protocol.verbs.motion import MOTION_MODES
from ..protocol.verbs.queries import Where
from .connect import ServerUnavailable, dial
from .options import COMMANDS_DIR, add_connection_args, default_address, find_script, server_address

__all__ = [
    "COMMANDS_DIR",
    "Client",
    "ConnectionLost",
    "ServerUnavailable",
    "add_connection_args",
    "default_address",
    "find_script",
    "motion_of",
    "server_address",
]

_FIRST_DELAY_S = 0.05
_UNKNOWN_COMMAND = "error: unknown command"
_MAX_DELAY_S = 1.0


class ConnectionLost(C2rvizError):
    """The server closed the connection (it stopped, restarted or dropped us)."""

    def __init__(self, host: str, port: int) -> None:
        self.host = host
        self.port = port
        super().__init__(f"connection to {host}:{port} lost (the server stopped or restarted)")


def motion_of(reply: str) -> str | None:
    """The connection's motion mode from the reply to a bare ``motion``.

    Args:
        reply: The server's reply: ``ok off|on|follow``, or an older server's
            ``error: unknown command 'motion' ...``.

    Returns:
        ``off``, ``on`` or ``follow``; None when the server has no motion.

    Raises:
        C2rvizError: any other reply.
    """
    if reply.startswith("ok "):
        mode = reply[3:].strip()
        if mode in MOTION_MODES:
            return mode
    elif reply.startswith(_UNKNOWN_COMMAND):
        return None
    raise C2rvizError(f"unexpected reply to 'motion': {reply!r}")


class Client:
    """One connection to the command server: a line out, a reply line back, in order.

    The connection opens lazily (``open`` or the first ``send``). Replies are
    matched to lines by order, so several lines may be sent before their
    replies are read (pipelining). An interrupted read or write leaves the
    stream out of step, so the connection is closed; the next ``send``
    reconnects and restores the unit mode and the robot chosen.

    Attributes:
        degrees: The connection's angle unit as last confirmed by the server.
        chosen_robot: The robot a ``robot NAME`` line chose (the server said ``ok``);
            None: the port's own robot.
        robot, joint_names: From ``names``, once ``joint_names()`` has asked (asked
            again after ``robot NAME``).
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
        self.chosen_robot: str | None = None
        self.robot: str | None = None
        self._names: tuple[str, ...] | None = None
        self._sock: socket.socket | None = None
        self._received = bytearray()  # read from the socket, not yet a whole reply
        self._sent: deque[Units | RobotChoice | None] = deque()  # one per reply to read

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
        sock = dial(self.host, self.port, self.retry_s, self.notify)
        self._sock = sock
        self._received.clear()
        self._sent.clear()
        self._names = None
        if self.chosen_robot is not None:
            reply = self.ask(f"robot {self.chosen_robot}")
            if not reply.startswith("ok"):  # the restarted server has no such robot
                self.chosen_robot = None
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
        self._received.clear()
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
        self._sent.append(command if isinstance(command, (Units, RobotChoice)) else None)
        return True

    def read_reply(self, *, interruptible: bool = False) -> str:
        """The reply to the oldest unanswered line, without its newline.

        Args:
            interruptible: Ctrl-C while waiting leaves the connection open and the
                reply still due (the caller reads it later, e.g. after sending
                ``stop`` on another connection). By default the connection is
                closed, since the reply would otherwise arrive late.

        Raises:
            ConnectionLost: the server closed the connection first.
        """
        if not self._sent or self._sock is None:
            raise RuntimeError("read_reply() with no line waiting for its reply")
        try:
            raw = self._read_line()
        except OSError:
            raw = b""
        except BaseException:  # Ctrl-C while waiting: what arrived stays in the buffer
            if not interruptible:
                self.close()
            raise
        if not raw.endswith(b"\n"):
            self.close()
            raise ConnectionLost(self.host, self.port)
        tracked = self._sent.popleft()
        reply = raw.decode("utf-8", "replace").rstrip("\r\n")
        if reply.startswith("ok"):
            if isinstance(tracked, Units):
                self.degrees = tracked.degrees
            elif isinstance(tracked, RobotChoice) and tracked.name is not None:
                self.chosen_robot = tracked.name
                self._names = None  # another robot: other joints
        return reply

    def _read_line(self) -> bytes:
        """The next line from the server with its newline; at EOF what came (maybe b"").

        An interrupted wait loses nothing: what has arrived stays in the buffer.
        """
        assert self._sock is not None
        received = self._received
        searched = 0
        while (end := received.find(b"\n", searched)) < 0:
            searched = len(received)
            chunk = self._sock.recv(65536)
            if not chunk:
                line = bytes(received)
                received.clear()
                return line
            received += chunk
        line = bytes(received[: end + 1])
        del received[: end + 1]
        return line

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

    def motion(self) -> str | None:
        """The connection's motion mode (``off``, ``on``, ``follow``); None when the
        server has no motion (it predates the ``motion`` verb).

        Raises:
            C2rvizError: the server answered ``motion`` with something else.
        """
        return motion_of(self.ask("motion"))
