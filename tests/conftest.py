"""Shared fixtures: a real server on 127.0.0.1:0 and plain-socket clients (the classes
behind them are in ``support.py``).

``start_server`` runs a real ``CommandServer`` (real Pinocchio robot, recording
scene) on its own asyncio loop in a thread, so tests talk to it exactly as a
controller would: through a TCP socket. ``c2rviz_process`` runs the whole
program as a subprocess for the tests that need ``main`` (quit, signals).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from browser_support import FreshContexts
from hypothesis import settings
from support import (
    ARGS,
    CHROMIUM,
    CI_EXAMPLES,
    Client,
    Process,
    ServerThread,
    load_robot,
    start_program,
)

from c2rviz.session import ServerLimits
from c2rviz.world.virtual_clock import VirtualClock


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "wall_clock(reason): start_server and server run on the real clock (else virtual): "
        "the test judges how long something took, or polls while the arm moves",
    )


settings.register_profile("ci", max_examples=CI_EXAMPLES, deadline=None, print_blob=True)
settings.register_profile("thorough", max_examples=100, deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
"""Hypothesis for every run of the suite: ``ci`` by default, ``HYPOTHESIS_PROFILE=thorough``
for the examples each property test ran before issue 36 (``default`` for hypothesis's own).
A profile's ``max_examples`` is per 100 of a test's thorough count (``support.examples``):
``ci`` runs CI_EXAMPLES in 100 (docs/testing.md: the counts, and the failures they still
catch). Both: no deadline (a time limit per example on the wall clock, 200 ms by default,
fails a test on a busy machine), and a failure's blob printed for ``@reproduce_failure``."""


@pytest.fixture
def start_server(request: pytest.FixtureRequest) -> Iterator[Callable[..., ServerThread]]:
    """Factory: ``start_server(robot="motoman_sia20d", **limits)``; always stopped. Each
    server runs on a virtual clock of its own unless the test is marked ``wall_clock``."""
    started: list[ServerThread] = []
    wall = request.node.get_closest_marker("wall_clock") is not None

    def start(robot: str = "motoman_sia20d", **limits: Any) -> ServerThread:
        clock = None if wall else VirtualClock()
        server = ServerThread(load_robot(robot), ServerLimits(**limits), clock=clock).start()
        started.append(server)
        return server

    yield start
    for server in started:
        server.stop()


@pytest.fixture
def server(start_server: Callable[..., ServerThread]) -> ServerThread:
    """A live motoman server with default limits (virtual time unless ``wall_clock``)."""
    return start_server()


@pytest.fixture
def connect() -> Iterator[Callable[[ServerThread], Client]]:
    """Factory: ``connect(server)`` opens a client; all are closed afterwards."""
    clients: list[Client] = []

    def open_client(server: ServerThread) -> Client:
        client = Client(server.host, server.port)
        clients.append(client)
        return client

    yield open_client
    for client in clients:
        client.close()


@pytest.fixture
def c2rviz_process() -> Iterator[Callable[..., Process]]:
    """Factory: start ``python -m c2rviz --port 0 ARGS`` (``--no-rosbridge`` too, unless ARGS
    name ``--rosbridge-port``, and ``--crcl-port 0`` unless they name CRCL's or ask for
    its ``default_crcl_port``); waits until it listens."""
    procs: list[Process] = []

    def start(*args: str, timeout: float = 120.0, default_crcl_port: bool = False) -> Process:
        proc = start_program(*args, timeout=timeout, default_crcl_port=default_crcl_port)
        procs.append(proc)
        return proc

    yield start
    for proc in procs:
        proc.stop()


@pytest.fixture(scope="session")
def chromium() -> Iterator[Any]:
    """The session's one headless Chromium (Playwright), launched on first use; a CI run
    without it fails rather than skips. Tests take ``browser``, not this."""
    if not CHROMIUM.exists():
        if os.environ.get("CI") == "true":
            pytest.fail(f"{CHROMIUM} is missing: install Debian's chromium")
        pytest.skip(f"{CHROMIUM} is missing")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = FreshContexts(
            lambda: pw.chromium.launch(executable_path=str(CHROMIUM), args=ARGS)
        )
        try:
            yield browser
        finally:
            browser.resume()
            browser.close()


@pytest.fixture
def browser(chromium: FreshContexts) -> Iterator[FreshContexts]:
    """The session's Chromium for one test: each page in a new context of its own, every
    context the test opened closed after it (one launch per session, not per test)."""
    chromium.resume()
    try:
        yield chromium
    finally:
        chromium.close_contexts()


BROWSER_TIMEOUT_S = 900
"""A browser test's own time limit [s]: it starts the program and Chromium and waits for
pictures, each wait bounded by browser_support.DEADLINE_S (180 s). The suite's 120 s
limit cut such a test short on a busy 2-core machine before its own waits failed."""


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if item.get_closest_marker("browser") and not item.get_closest_marker("timeout"):
            item.add_marker(pytest.mark.timeout(BROWSER_TIMEOUT_S))
