"""The seed's door, listening: a TCP server whose every connection is a ``tcp_text.Connection``.

It holds the connections being served and those refused until their sockets close,
tells the program how many clients it serves, and at shutdown answers and closes
every client before it frees its port.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from ..protocol import replies
from ..session.services import Services
from .tcp_text import Connection

log = logging.getLogger("c2rviz.server")


class CommandServer:
    """Listens for TCP clients and runs each one's lines against one ``World``."""

    def __init__(
        self,
        services: Services,
        on_quit: Callable[[], None] | None = None,
        robot: str | None = None,
        viewer_url: str | None = None,
    ) -> None:
        """Set up the server; ``start`` makes it listen.

        Args:
            services: The world every client acts on, and what sessions share (its
                ``limits`` say what one client may cost).
            on_quit: Called once when a client sends ``quit``.
            robot: The robot its clients drive until they say ``robot NAME`` (None:
                the world's default).
            viewer_url: The page's address, told to a browser that opens the
                command port (None: no viewer). The attribute may be set later,
                once the viewer is up.
        """
        self.services = services
        self.world = services.world
        self.viewer_url = viewer_url
        self.limits = services.limits
        self.on_quit = on_quit
        self.robot = robot
        self.connections: set[Connection] = set()  # the clients being served
        self.open: set[Connection] = set()  # those and the refused ones, until their socket closes
        self.stopping = False
        self.quit_requested = False
        self._server: asyncio.Server | None = None
        self._door = f"tcp {id(self)}"

    def count_clients(self) -> None:
        """Tell the program how many clients this door serves now."""
        self.services.count_clients(self._door, len(self.connections))

    def admit(self, connection: Connection) -> str | None:
        """A client has connected: serve it, or say why not (None: served; else the reply
        it gets before it is closed: the server stops, or ``max_clients`` are served)."""
        self.open.add(connection)
        if self.stopping:
            return replies.SHUTTING_DOWN
        served = len(self.connections)
        if served >= self.limits.max_clients:
            log.warning("refused %s: %d clients already", connection.peer, served)
            return replies.too_many_clients(self.limits.max_clients)
        self.connections.add(connection)
        self.count_clients()
        log.info("client %s connected", connection.peer)
        return None

    def release(self, connection: Connection) -> None:
        """A client's socket has closed: it is served no more."""
        self.open.discard(connection)
        if connection in self.connections:
            self.connections.discard(connection)
            self.count_clients()
            log.info("client %s left", connection.peer)

    async def start(self, host: str = "127.0.0.1", port: int = 0) -> tuple[str, int]:
        """Start listening; return the address actually bound (port 0 picks one)."""
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(lambda: Connection(self), host, port)
        bound = self._server.sockets[0].getsockname()
        self.world.faults.listeners.append(self._fault)
        return bound[0], bound[1]

    def _fault(self, robot: str, text: str) -> None:
        if text == "fault disconnect":  # this robot's clients are cut off (they may come back)
            for connection in [c for c in self.connections if c.session.state.name == robot]:
                connection.drop()

    def request_quit(self) -> None:
        if not self.quit_requested:
            self.quit_requested = True
            log.info("quit requested by a client")
            if self.on_quit is not None:
                self.on_quit()

    async def stop(self, grace_s: float = 1.0) -> None:
        """Stop accepting, answer and close every client, free the port."""
        self.stopping = True
        if self._fault in self.world.faults.listeners:
            self.world.faults.listeners.remove(self._fault)
        if self._server is not None:
            self._server.close()
            # A socket accepted just before has its transport made but its connection_made
            # still queued: let those run, so every connection is in the sets closed below
            # (else its transport is never closed: a ResourceWarning when it is collected).
            for _ in range(3):
                await asyncio.sleep(0)
        for connection in list(self.connections):
            connection.shutdown()
        if self.open:  # each gets its last replies and then closes, or is cut off
            await asyncio.wait([c.closed for c in self.open], timeout=grace_s)
        left = list(self.open)
        for connection in left:
            if connection.transport is not None:
                connection.transport.abort()
        if left:  # let connection_lost run, so every socket is closed when we return
            await asyncio.wait([c.closed for c in left], timeout=1.0)
        if self._server is not None:
            await self._server.wait_closed()
