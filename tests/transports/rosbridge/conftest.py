"""Fixtures: the in-test bridge, the server's policy, and the server on 127.0.0.1:0."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from rosbridge_support import CounterBridge, ServerThread

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
