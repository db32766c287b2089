"""The CRCL door of the program: a ``CrclServer`` per robot, opened beside the text ports.

One robot listens on ``crcl_port`` (64444 unless ``--crcl-port`` or the ini's
``crcl_port`` says otherwise; 0 picks a free port); in a cell each robot has its own,
the first on that port and the next ones on the ports after it (as each has its own
text port). ``--no-crcl`` opens none. The address is the text port's (``--host``,
loopback by default). A default port that is taken costs only the CRCL door (said in
one line); a named one that is taken stops the program (``doors.open_port``).
Importing this module adds its opener to ``doors.OPENERS``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..errors import ConfigError
from ..session.services import Services
from ..transports.crcl.server import DEFAULT_PORT, CrclLimits, CrclServer
from .config import Settings
from .doors import OPENERS, Door, Opened, close_doors, open_port
from .members import Member

__all__ = ["open_crcl"]


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


OPENERS.append(open_crcl)
