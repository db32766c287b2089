"""The doors beside the text port: each opened on the same session path, each closed at exit.

A door (CRCL, rosbridge) is a transport: it turns its clients' bytes into commands on a
``Session`` and the world's effects into its own messages. The program opens every door
the settings ask for after the command ports and before the page, and stops them all
before the world closes.

An *opener* is ``async opener(settings, services, members, on_quit) -> list[Opened]``;
``OPENERS`` (at the end) names them in the order they open: a new door adds its opener
there. ``open_port`` gives every door the same rule for its port: a port the user named
that is taken is an error (the program stops with status 2, as for ``--port``); a
default port that is taken costs only that door, said in one line.

The CRCL door (``open_crcl``): a ``CrclServer`` per robot. One robot listens on
``crcl_port`` (64444 unless ``--crcl-port`` or the ini's ``crcl_port`` says otherwise; 0
picks a free port); in a cell each robot has its own, the first on that port and the next
ones on the ports after it (as each has its own text port). ``--no-crcl`` opens none. The
address is the text port's (``--host``, loopback by default).

The rosbridge door (``open_rosbridge``, ``RosbridgeDoor``): ROS web tools and scripts talk
to the program at ``ws://HOST:9090/``, unless ``--no-rosbridge``: one endpoint for every
robot (in a cell each under its namespace), on the command server's ``--host`` at
``--rosbridge-port`` (ini ``rosbridge_port``; 9090 by default). It is guarded as the page
is: browsers from the ``--viewer-origin`` list (and loopback pages) only, and the viewer's
token (``--viewer-token``, or one made for this run when the door listens beyond loopback)
in ``?token=``. Its limits are ``RosbridgePolicy``'s (frame size, connections,
subscriptions).
"""

from __future__ import annotations

import errno
import ipaddress
import secrets
import sys
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..errors import C2rvizError, ConfigError, shown
from ..ini import normalize_origin
from ..session.services import Services
from ..transports.crcl.server import DEFAULT_PORT, CrclLimits, CrclServer
from ..transports.rosbridge import PolicyError, RosbridgePolicy, RosbridgeServer
from ..transports.rosbridge.robot_bridge import RobotBridge
from .config import Settings
from .members import Member


class Door(Protocol):
    """An open door: it stops when the program does."""

    async def stop(self) -> None: ...


@dataclass(frozen=True)
class Opened:
    """A door that opened, the line the banner says of it, and a warning if it has one
    (printed with the program's, e.g. listening beyond loopback)."""

    door: Door
    banner: str
    warning: str | None = None


Opener = Callable[
    [Settings, Services, Sequence[Member], Callable[[], None]], Awaitable[list[Opened]]
]
"""``opener(settings, services, members, on_quit)``: open a kind of door (none, one, or one
per robot) as the settings say; raise ``ConfigError`` to stop the program (status 2)."""


async def open_port(
    what: str, flag: str, host: str, port: int, named: bool, start: Callable[[int], Awaitable[Door]]
) -> Door | None:
    """Start a door with ``start(port)``; a port in use stops the program if the user named
    it (``named``), else the program goes on without this door and says so in one line.

    Args:
        what: The door, for messages ("CRCL", "rosbridge").
        flag: The flag that chooses its port (``--crcl-port``), for the hint.
        host: The address it listens on.
        port: The port.
        named: The user chose the port (a flag or the ini), rather than the default.
        start: Starts the door on a port; raises OSError when it cannot listen.

    Raises:
        ConfigError: a named port is taken, or the door cannot listen at all.
    """
    try:
        return await start(port)
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE and not named:
            print(
                f"c2rviz: {what} port {port} is in use (another c2rviz?): no {what} door "
                f"this time ({flag} N chooses another, 0 a free one)",
                file=sys.stderr,
                flush=True,
            )
            return None
        if exc.errno == errno.EADDRINUSE:
            raise ConfigError(
                f"cannot listen for {what} on {host}:{port}: the port is in use; choose another "
                f"with {flag} (0 picks a free one)"
            ) from None
        raise ConfigError(
            f"cannot listen for {what} on {host}:{port}: {exc.strerror or exc}"
        ) from None


async def open_doors(
    settings: Settings,
    services: Services,
    members: Sequence[Member],
    on_quit: Callable[[], None],
) -> list[Opened]:
    """Open every door the settings ask for; on an error close those opened and raise."""
    opened: list[Opened] = []
    try:
        for opener in OPENERS:
            opened.extend(await opener(settings, services, members, on_quit))
    except BaseException:
        await close_doors(opened)
        raise
    return opened


async def close_doors(opened: Sequence[Opened]) -> None:
    """Stop every door (the last opened first)."""
    for entry in reversed(opened):
        await entry.door.stop()


async def open_crcl(
    settings: Settings,
    services: Services,
    members: Sequence[Member],
    on_quit: Callable[[], None],
) -> list[Opened]:
    """A CRCL server per robot, as the settings say (none with ``--no-crcl``).

    Raises:
        ConfigError: a named port is taken, or a cell's ports would pass 65535.
    """
    if not settings.crcl:
        return []
    named = settings.crcl_port is not None
    base = settings.crcl_port if settings.crcl_port is not None else DEFAULT_PORT
    if base and base + len(members) - 1 > 65535:
        raise ConfigError(
            f"--crcl-port {base} leaves no room for {len(members)} robots' CRCL ports "
            "(each takes the next one; the last must be at most 65535)"
        )
    limits = CrclLimits(max_unread=settings.limits.max_unread)
    in_cell = len(members) > 1
    opened: list[Opened] = []
    try:
        for index, member in enumerate(members):
            server = CrclServer(services, member.name, limits)

            async def start(port: int, server: CrclServer = server) -> Door:
                await server.start(settings.host, port)
                return server

            port = base + index if base else 0
            door = await open_port("CRCL", "--crcl-port", settings.host, port, named, start)
            if door is None:  # a default port is taken: no CRCL door this time
                await close_doors(opened)
                return []
            host, bound = server.address or (settings.host, port)
            who = f"{member.name}: " if in_cell else ""
            opened.append(Opened(server, f"{who}CRCL on {host}:{bound} (docs/crcl.md)"))
    except BaseException:
        await close_doors(opened)
        raise
    return opened


DEFAULT_ROSBRIDGE_PORT = 9090
"""rosbridge's conventional port."""


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _check_viewer_settings(settings: Settings) -> None:
    """Refuse a ``--viewer-origin`` or ``--viewer-token`` that cannot work, in the viewer's
    words: the door shares them and opens first (the page is not loaded to check them).

    Raises:
        ConfigError: naming the setting and what it must be.
    """
    for origin in settings.viewer_origins:
        if normalize_origin(origin) is None:
            raise ConfigError(
                f"viewer origin {shown(origin)} is not scheme://host[:port] (http or https)"
            )
    token = settings.viewer_token
    if token is not None and not (token.isascii() and token.isprintable()):
        raise ConfigError(f"viewer token {shown(token)} is not printable ASCII")


class RosbridgeDoor:
    """The rosbridge server and the bridge to the world behind it, stopped together."""

    def __init__(self, services: Services, settings: Settings, on_quit: Callable[[], None]):
        """Make the bridge and the server (not yet listening).

        Raises:
            C2rvizError: a robot's URDF cannot be read as TF, or a bad origin or token.
        """
        self.token = settings.viewer_token
        if self.token is None and not _is_loopback(settings.host):
            self.token = secrets.token_urlsafe(16)
        policy = RosbridgePolicy(extra_origins=settings.viewer_origins, token=self.token)
        self.bridge = RobotBridge(services, cell=settings.cell is not None, on_quit=on_quit)
        self.server = RosbridgeServer(self.bridge, policy)
        self.host, self.port, self.url = "", 0, ""
        """Where it listens, once started (``url`` with the token, if any)."""

    async def start(self, host: str, port: int) -> RosbridgeDoor:
        """Listen on ``host:port`` (0: a free port); ``host``, ``port`` and ``url`` say where."""
        self.host, self.port = await self.server.start(host, port)
        shown = f"[{self.host}]" if ":" in self.host else self.host
        query = f"?token={self.token}" if self.token is not None else ""
        self.url = f"ws://{shown}:{self.port}/{query}"
        return self

    async def stop(self) -> None:
        """Close every connection and the port; drop the sessions; idempotent."""
        await self.server.stop()
        self.bridge.close()


async def open_rosbridge(
    settings: Settings,
    services: Services,
    members: Sequence[Member],
    on_quit: Callable[[], None],
) -> list[Opened]:
    """Open the rosbridge door as the settings say (none with ``--no-rosbridge``).

    Raises:
        C2rvizError: a bad ``--viewer-origin`` or ``--viewer-token`` (as the viewer
            words it), or a named port that is taken.
    """
    if not settings.rosbridge:
        return []
    _check_viewer_settings(settings)
    try:
        door = RosbridgeDoor(services, settings, on_quit)
    except PolicyError as exc:  # a --viewer-origin or --viewer-token that cannot work
        raise ConfigError(str(exc)) from None
    except C2rvizError as exc:  # a robot whose URDF is no TF tree: the rest goes on
        print(f"c2rviz: no rosbridge door: {exc}", file=sys.stderr, flush=True)
        return []
    named = settings.rosbridge_port is not None
    port = DEFAULT_ROSBRIDGE_PORT if settings.rosbridge_port is None else settings.rosbridge_port

    async def start(chosen: int) -> Door:
        return await door.start(settings.host, chosen)

    try:
        started = await open_port(
            "rosbridge", "--rosbridge-port", settings.host, port, named, start
        )
    except BaseException:
        door.bridge.close()
        raise
    if started is None:
        door.bridge.close()
        return []
    spaces = [t.namespace for t in door.bridge.robots.values() if t.namespace]
    where = f"robots under /{', /'.join(spaces)}" if spaces else "/joint_states, /tf"
    warning = None
    if not _is_loopback(settings.host):
        made = " (generated for this run; --viewer-token sets one)"
        warning = (
            f"rosbridge listens on {settings.host}: anyone who can reach it and has its URL "
            f"with the token can move the robot{made if settings.viewer_token is None else ''}"
        )
    banner = f"rosbridge at {door.url} ({where}; docs/rosbridge.md)"
    return [Opened(door, banner, warning)]


OPENERS: tuple[Opener, ...] = (open_crcl, open_rosbridge)
"""Every kind of door besides the text port, in the order they open."""
