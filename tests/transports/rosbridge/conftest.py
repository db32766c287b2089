"""Fixtures: the in-test bridge, the server's policy, and the server on 127.0.0.1:0; a real
c2rviz server with the rosbridge door (``world_server``) and roslibpy connected to it."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
import roslibpy
from rosbridge_support import CounterBridge, ServerThread
from roslibpy.ros import set_rosapi_timeout
from support import load_robot
from world_support import WAIT_S, WorldServer

from c2rviz.transports.rosbridge import RosbridgePolicy


@pytest.fixture
def bridge() -> CounterBridge:
    return CounterBridge()


@pytest.fixture
def policy() -> RosbridgePolicy:
    """The server's policy; a test module or test overrides it for tighter limits."""
    return RosbridgePolicy()


@pytest.fixture
def rosbridge(bridge: CounterBridge, policy: RosbridgePolicy) -> Iterator[ServerThread]:
    server = ServerThread(bridge, policy)
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture
def world_server() -> Iterator[WorldServer]:
    """A real c2rviz server (motoman alone): world, text port and the rosbridge door."""
    server = WorldServer({"motoman_sia20d": load_robot("motoman_sia20d")})
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture
def ros_world(world_server: WorldServer) -> Iterator[roslibpy.Ros]:
    """roslibpy (asyncio transport) connected to ``world_server``."""
    set_rosapi_timeout(WAIT_S)
    client = roslibpy.Ros("127.0.0.1", world_server.port, transport="asyncio")
    client.run(timeout=WAIT_S)
    try:
        yield client
    finally:
        client.close()
