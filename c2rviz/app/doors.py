"""The doors beside the text port: each opened on the same session path, each closed at exit.

A door (CRCL, rosbridge, ...) is a transport: it turns its clients' bytes into
commands on a ``Session`` and the world's effects into its own messages. The
program opens every door the settings ask for after the command ports and
before the page, and stops them all before the world closes.

An *opener* is ``async opener(settings, services, members, on_quit) -> list[Opened]``;
``OPENERS`` lists them in the order they open (a door module adds its own).
``open_port`` gives every door the same rule for its port: a port the user named
that is taken is an error (the program stops with status 2, as for ``--port``); a
default port that is taken costs only that door, said in one line.
"""

from __future__ import annotations

import errno
import sys
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from ..errors import ConfigError
from ..session.services import Services
from .config import Settings
from .members import Member

__all__ = ["OPENERS", "Door", "Opened", "Opener", "close_doors", "open_doors", "open_port"]


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

OPENERS: list[Opener] = []
"""Every kind of door besides the text port, in the order they open."""


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
