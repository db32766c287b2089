"""The rosbridge door: ROS web tools and scripts talk to the program at ``ws://HOST:9090/``.

Opened by ``open_rosbridge`` (one of ``doors.OPENERS``) unless ``--no-rosbridge``:
one endpoint for every robot (in a cell each under its namespace), on the
command server's ``--host`` (loopback by default) at ``--rosbridge-port`` (ini
``rosbridge_port``; 9090 by default). A taken default port costs only this
door, in one line; a port the user named that is taken stops the program.

It is guarded as the page is: browsers from the ``--viewer-origin`` list (and
loopback pages) only, and the viewer's token (``--viewer-token``, or one made
for this run when the door listens beyond loopback) in ``?token=``. Its limits
are ``RosbridgePolicy``'s (frame size, connections, subscriptions).
"""

from __future__ import annotations

import ipaddress
import secrets
import sys
from collections.abc import Callable, Sequence

from ..errors import C2rvizError, ConfigError, shown
from ..session.services import Services
from ..transports.rosbridge import PolicyError, RosbridgePolicy, RosbridgeServer
from ..transports.rosbridge.policy import normalize_origin
from ..transports.rosbridge.robot_bridge import RobotBridge
from .config import Settings
from .doors import OPENERS, Door, Opened, open_port
from .members import Member

__all__ = ["DEFAULT_ROSBRIDGE_PORT", "RosbridgeDoor", "open_rosbridge"]

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


OPENERS.append(open_rosbridge)
