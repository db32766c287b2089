"""Shared fixtures: a real server on 127.0.0.1:0 and plain-socket clients (the classes
behind them are in ``support.py``).

``start_server`` runs a real ``CommandServer`` (real Pinocchio robot, recording
scene) on its own asyncio loop in a thread, so tests talk to it exactly as a
controller would: through a TCP socket. ``c2rviz_process`` runs the whole
program as a subprocess for the tests that need ``main`` (quit, signals).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from browser_support import FreshContexts
from hypothesis import settings
from support import (
    ARGS,
    CHROMIUM,
    CI_EXAMPLES,
    ROOT,
    Client,
    Process,
    ServerThread,
    load_robot,
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
        # No rosbridge door (port 9090) unless the test names its port: tests stay apart.
        door = () if any(a.startswith("--rosbridge-port") for a in args) else ("--no-rosbridge",)
        named = any(a.startswith(("--crcl-port", "--no-crcl")) for a in args)
        if not (named or default_crcl_port):
            door += ("--crcl-port", "0")  # a free port: not 64444, which may be taken
        popen = subprocess.Popen(
            [sys.executable, "-m", "c2rviz", "--port", "0", *door, *args],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        output: list[str] = []
        deadline = time.monotonic() + timeout
        port = None
        url = None
        no_viewer = "--no-viewer" in args
        assert popen.stdout is not None
        while time.monotonic() < deadline:
            line = popen.stdout.readline()
            if not line:
                break
            output.append(line)
            if m := re.search(r"commands on [\d.]+:(\d+)", line):
                port = int(m.group(1))
            if m := re.search(r"viewer at (\S+)", line):
                url = m.group(1)
            if port is not None and (no_viewer or url is not None):
                break
        if port is None:
            popen.kill()
            raise RuntimeError("c2rviz did not start:\n" + "".join(output))
        proc = Process(popen, port, output, url)
        procs.append(proc)
        return proc

    yield start
    for proc in procs:
        if proc.popen.poll() is None:
            proc.popen.kill()
            proc.popen.wait(timeout=10)
        if proc.popen.stdout is not None:
            proc.popen.stdout.close()


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
