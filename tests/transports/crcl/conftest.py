"""Fixtures: a live server with the text port and the CRCL door, and CRCL clients."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from crcl_support import CrclClient, CrclServerThread
from support import load_robot

from c2rviz.session import ServerLimits
from c2rviz.transports.crcl.server import CrclLimits


@pytest.fixture
def start_crcl(request: pytest.FixtureRequest) -> Iterator[Callable[..., CrclServerThread]]:
    """Factory: ``start_crcl(robot="motoman_sia20d", limits=ServerLimits(), **crcl_limits)``;
    virtual time unless the test is marked ``wall_clock``."""
    started: list[CrclServerThread] = []
    wall = request.node.get_closest_marker("wall_clock") is not None

    def start(
        robot: str = "motoman_sia20d", limits: ServerLimits | None = None, **crcl: Any
    ) -> CrclServerThread:
        server = CrclServerThread(
            load_robot(robot),
            limits or ServerLimits(),
            crcl_limits=CrclLimits(**crcl),
            **({"clock": None} if wall else {}),
        )
        started.append(server.start())
        return server

    yield start
    for server in started:
        server.stop()


@pytest.fixture
def crcl_server(start_crcl: Callable[..., CrclServerThread]) -> CrclServerThread:
    """A live motoman server: text port and CRCL door, default limits."""
    return start_crcl()


@pytest.fixture
def crcl_connect() -> Iterator[Callable[[CrclServerThread], CrclClient]]:
    """Factory: ``crcl_connect(server)`` opens a CRCL client; all are closed afterwards."""
    clients: list[CrclClient] = []

    def open_client(server: CrclServerThread) -> CrclClient:
        client = CrclClient(server.host, server.crcl_port)
        clients.append(client)
        return client

    yield open_client
    for client in clients:
        client.close()
