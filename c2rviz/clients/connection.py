"""Reaching the command server: where it is, dialling it, and what a connection remembers.

Where: what a client takes from its flags and the ini (``add_connection_args``,
``server_address``), and where command files are (``find_script``: the working directory,
then the recording folder, then the project's ``commands/``). Shared by ``c2rviz-cli`` and
``c2rviz-play``; it reads the ini with the settings reader alone: no robot is loaded.

Dialling: the server may be starting or restarting when a client begins: ``dial``
retries a refused connection with a growing delay (0.05 s doubling to 1 s) for up to
``retry_s`` seconds, says once that it is waiting, and then gives up with
``ServerUnavailable``.

Remembering: ``LineClient`` (a blocking socket) and ``AsyncLineClient`` (asyncio streams)
differ in how they read and write; what they remember is the same, and is kept here once
(``LineState``): the server's address and limits, the unit mode and the robot the
connection chose (which a reconnect restores), and the robot's joint names (asked once per
connection and robot). No I/O there.
"""

from __future__ import annotations

import argparse
import socket
import time
from collections.abc import Callable
from pathlib import Path

from ..errors import C2rvizError
from ..ini import INI_NAME, PROJECT_DIR, address, find_ini, read_ini
from ..protocol.verbs.arm import RobotChoice
from ..protocol.verbs.seed import Units
from .errors import CommandError, UnexpectedReply

COMMANDS_DIR = PROJECT_DIR / "commands"
"""The project's bundled command files."""


def add_connection_args(parser: argparse.ArgumentParser) -> None:
    """The flags every client shares: where the server is and how long to retry."""
    add = parser.add_argument
    add("--host", help="command server (default from cmdinterpreter.ini: 127.0.0.1)")
    add("--port", type=int, help="command port (default from cmdinterpreter.ini: 31000)")
    add("--config", metavar="PATH", help="ini file for host and port")
    add(
        "--timeout",
        type=float,
        default=10.0,
        metavar="S",
        help="keep retrying the connection for S seconds, then give up (default 10)",
    )


def default_address(config: str | Path | None = None) -> tuple[str, int]:
    """Host and port from cmdinterpreter.ini (``[options] host/port``), else 127.0.0.1:31000.

    An unspecified bind address (``0.0.0.0``, ``::``) in the ini means "this machine"
    to a client, so it becomes the loopback address.

    Raises:
        ConfigError: ``config`` does not exist, or the ini has a bad value.
    """
    host, port = address(find_ini(config))
    if host in ("", "0.0.0.0"):
        host = "127.0.0.1"
    elif host == "::":
        host = "::1"
    return host, port


def server_address(
    host: str | None, port: int | None, config: str | Path | None = None
) -> tuple[str, int]:
    """Where to connect: ``--host``/``--port`` where given, the rest from the ini.

    Args:
        host: The ``--host`` flag (None: not given).
        port: The ``--port`` flag (None: not given; 0 is a port).
        config: The ``--config`` flag (None: the usual ini search).

    Raises:
        ConfigError: the ini is needed and ``config`` does not exist or has a bad value.
    """
    if host is not None and port is not None:
        return host, port
    ini_host, ini_port = default_address(config)
    return host or ini_host, ini_port if port is None else port


def recording_folder(config: str | Path | None = None) -> Path:
    """Where the server puts recordings, as a client reads the ini: the user's ini's
    ``[options] record_dir`` (relative to that ini), else ``./recordings`` of the working
    directory (the project's own ini does not count: its folder is not the user's).

    A bad or unreadable ini is no reason to fail a search: ``./recordings`` then.
    """
    here = Path.cwd() / "recordings"
    try:
        ini = find_ini(config)
        if ini is None or ini.resolve() == (PROJECT_DIR / INI_NAME).resolve():
            return here
        folder = read_ini(ini).get("options", "record_dir", fallback=None)
    except C2rvizError:
        return here
    return here if not folder else ini.parent / folder


def find_script(name: str | Path, config: str | Path | None = None) -> Path:
    """A command file: ``name`` as given (relative to the working directory), else in
    the recording folder (``recording_folder``), else in the project's ``commands/``.

    Raises:
        FileNotFoundError: in none of them (the message names each place looked in).
    """
    path = Path(name)
    if path.is_file():
        return path
    looked = [str(path if path.is_absolute() else Path.cwd() / path)]
    if not path.is_absolute():
        for folder in (recording_folder(config), COMMANDS_DIR):
            candidate = folder / path
            if candidate.is_file():
                return candidate
            looked.append(str(candidate))
    raise FileNotFoundError(f"no command file {str(name)!r}: looked for {', '.join(looked)}")


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


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def dial(
    host: str, port: int, retry_s: float, notify: Callable[[str], None] | None = None
) -> socket.socket:
    """A blocking TCP connection to ``host:port`` (no timeout, no Nagle delay).

    Args:
        host, port: The command server.
        retry_s: How long to keep retrying a refused connection [s].
        notify: Called once with a short message when retrying begins.

    Raises:
        ServerUnavailable: nothing accepted the connection in time, or the host
            name does not resolve.
    """
    start = time.monotonic()
    deadline = start + retry_s
    delay = _FIRST_DELAY_S
    told = False
    while True:
        try:
            sock = socket.create_connection((host, port), timeout=5.0)
            break
        except socket.gaierror as exc:  # a bad host name does not get better
            raise ServerUnavailable(host, port, 0.0, _reason(exc)) from None
        except OSError as exc:
            left = deadline - time.monotonic()
            if left <= 0:
                waited = time.monotonic() - start
                raise ServerUnavailable(host, port, waited, _reason(exc)) from None
            if not told and notify is not None:
                notify(
                    f"no server at {host}:{port} yet ({_reason(exc)}); "
                    f"retrying for up to {retry_s:g} s"
                )
                told = True
            time.sleep(min(delay, left))
            delay = min(delay * 2, _MAX_DELAY_S)
    sock.settimeout(None)  # a reply may follow a long server-side sleep
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock


MAX_REPLY_BYTES = 1 << 20
"""Longest reply line a client reads [bytes]; past it the connection is closed."""


class LineState:
    """A connection's memory (see the module docstring).

    Attributes:
        host, port: The command server.
        timeout: Longest wait for one reply [s] (None: as long as it takes: a reply may
            follow a long move or ``sleep``).
        retry_s: How long to keep retrying a refused connection [s].
        max_reply: Longest reply line [bytes].
        chosen_robot: The robot a ``robot NAME`` line chose (the server said ``ok``);
            None: the port's own robot.
        robot_name, names: From ``names``, once ``joint_names()`` has asked.
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
    ) -> None:
        """Args:
        host, port: The command server.
        timeout: Longest wait for one reply [s]; None: no limit.
        retry_s: How long to keep retrying a refused connection [s].
        degrees: Speak degrees (the connection sends ``degrees`` when it opens).
        robot: Drive this robot of a cell (``robot NAME`` when it opens).
        max_reply: Longest reply line [bytes].
        """
        self.host = host
        self.port = port
        self.timeout = timeout
        self.retry_s = retry_s
        self.max_reply = max_reply
        self._degrees = degrees
        self.chosen_robot = robot
        self._insist = robot is not None  # the first open refuses a robot the server lacks
        self.robot_name: str | None = None
        self._names: tuple[str, ...] | None = None

    @property
    def in_degrees(self) -> bool:
        """The connection's angle unit is degrees (as last confirmed by the server)."""
        return self._degrees

    def _remember(self, reply: str, tracked: object) -> None:
        """After ``reply`` to a ``Units`` or ``RobotChoice`` command: what it chose."""
        if reply.startswith("ok"):
            if isinstance(tracked, Units):
                self._degrees = tracked.degrees
            elif isinstance(tracked, RobotChoice) and tracked.name is not None:
                self.chosen_robot = tracked.name
                self._names = None  # another robot: other joints

    def _robot_refused(self, line: str, reply: str) -> CommandError | None:
        """After restoring the chosen robot (``line``) on a new connection: the error to
        raise (the connection closed) when the robot chosen at construction is not the
        server's; a robot chosen later and gone from a restarted server is forgotten."""
        if reply.startswith("ok"):
            return None
        self.chosen_robot = None
        return CommandError(line, reply) if self._insist else None

    def _take_names(self, reply: str) -> tuple[str, ...]:
        """The joint names from the reply to ``names`` (remembered, with the robot's).

        Raises:
            CommandError: the server refused ``names``.
            UnexpectedReply: the reply is not a c2rviz one.
        """
        if reply.startswith("error"):
            raise CommandError("names", reply)
        robot, _, names = reply[3:].partition(" ")
        if not reply.startswith("ok ") or not robot or not names or " " in names:
            raise UnexpectedReply("names", reply)
        self.robot_name = robot
        self._names = tuple(names.split(","))
        return self._names
