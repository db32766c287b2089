"""What the tests share besides fixtures: the bundled robots, a live server on its own loop,
a plain-socket client, the program as a subprocess (``conftest.py`` makes fixtures of them).

Tests import these by name (``from support import load_robot``): ``tests/`` is on the
path because the root ``conftest.py`` lives there.
"""

from __future__ import annotations

import contextlib
import inspect
import os
import re
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

from hypothesis import settings

from c2rviz.robot.model import Robot
from c2rviz.session import ServerLimits
from c2rviz.testing.server import TestServer
from c2rviz.world.observer import RecordingScene
from c2rviz.world.virtual_clock import VirtualClock

ROOT = Path(__file__).resolve().parent.parent
CTRL_C_ABLE = [
    sys.executable,
    "-c",
    "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
    "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])",
]
"""The start of a child's argv that undoes an inherited "ignore SIGINT" (a job started in the
background by a shell gets one, and Python then never raises KeyboardInterrupt), so a test's
SIGINT acts as a Ctrl-C typed at a terminal."""
LIMITS_URDF = ROOT / "tests" / "data" / "limits_robot" / "limits.urdf"
"""A robot whose limits are at awkward numbers (puma560's +-1.570796325 rad)."""
CHROMIUM = Path("/usr/bin/chromium")  # Debian's; Playwright cannot download browsers here
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]
ROBOTS = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}

CI_EXAMPLES = 25
"""The ``ci`` hypothesis profile's examples per 100 of a test's thorough count (conftest)."""


def examples(thorough: int) -> int:
    """A property test's ``max_examples``: ``thorough`` (its count before issue 36) under
    ``HYPOTHESIS_PROFILE=thorough``, scaled by the loaded profile's ``max_examples`` per 100
    (``ci``: CI_EXAMPLES in 100), and at least 5. A failure a test once found is one of
    its ``@example``s, so every profile runs it (docs/testing.md)."""
    return max(5, round(thorough * settings.default.max_examples / 100))


@cache
def load_robot(name: str = "motoman_sia20d") -> Robot:
    """One of the bundled robots, with the ini's base and eelink (cached)."""
    path, base, eelink = ROBOTS[name]
    return Robot.from_urdf(ROOT / path, base, eelink)


@dataclass
class ServerThread:
    """A live server on its own loop and thread: the plugin's ``TestServer`` (the harness
    c2rviz's users get) with robots built here, a ``RecordingScene`` watching its world and
    the limits given. ``clock`` is a clock object: virtual time unless the test gives
    another (None: the wall clock, for a test that needs it)."""

    robot: Robot | Mapping[str, Robot]
    limits: ServerLimits
    scene: RecordingScene = field(default_factory=RecordingScene)
    quit: threading.Event = field(default_factory=threading.Event)
    host: str = "127.0.0.1"
    port: int = 0
    clock: Any = field(default_factory=VirtualClock)  # a world.clock.Clock; None: real time
    hz: float = 100.0
    record_dir: Path | None = None

    def start(self) -> ServerThread:
        options: dict[str, Any] = {"limits": self.limits, "hz": self.hz, "clock": self.clock}
        if self.record_dir is not None:
            options["record_dir"] = str(self.record_dir)
        harness = TestServer(options, robots=self.robot, observers=[self.scene])
        harness.keep_page(True)  # a recording writes its page, as the program's do
        self.harness = harness.start()
        self.loop = harness.loop
        self.thread = harness.thread
        self.world = harness.world
        self.services = harness.services
        self.server = harness.command_servers[0]
        self.quit = harness.quit_requested
        self.host, self.port = harness.host, harness.port
        return self

    def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        """Run ``fn(*args)`` on the server's loop and return its result."""
        return self.harness.call(fn, *args)

    def call_async(self, coro: Any) -> Any:
        return self.harness.call_async(coro)

    @property
    def q(self) -> tuple[float, ...]:
        """The shared joint values [rad], read on the server's loop."""
        return self.call(lambda: self.world.q)

    def stop(self) -> None:
        self.harness.stop()


class Client:
    """A controller's view of the server: a blocking TCP socket, one line at a time."""

    def __init__(self, host: str, port: int, timeout: float = 60.0) -> None:
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.file = self.sock.makefile("rb")

    def send(self, data: str | bytes) -> None:
        self.sock.sendall(data.encode() if isinstance(data, str) else data)

    def read_line(self) -> str:
        """The next reply line, without its newline ('' when the server closed)."""
        return self.file.readline().decode().rstrip("\n")

    def ask(self, line: str) -> str:
        """Send one command and return its reply."""
        self.send(line + "\n")
        return self.read_line()

    def closed_by_server(self) -> bool:
        """True when the server has closed the connection (reads EOF)."""
        try:
            return self.file.read() == b""  # reads to EOF: only returns once closed
        except (ConnectionResetError, TimeoutError):
            return False

    def close(self) -> None:
        self.file.close()
        self.sock.close()


@contextlib.contextmanager
def program_server(ini: Path) -> Iterator[TestServer]:
    """What ``c2rviz --config INI --no-viewer`` serves, in this process: the plugin's
    ``TestServer`` wires settings, robots and world as the program does, on the real clock
    as the program has it. For a test of what the ini puts in the world, not of the
    process (a subprocess costs 3-5 s of start-up on a busy machine)."""
    server = TestServer({"ini": str(ini), "clock": "real"}).start()
    try:
        yield server
    finally:
        server.stop()


@dataclass
class Process:
    """``python -m c2rviz`` running as a subprocess."""

    popen: subprocess.Popen[str]
    port: int
    output: list[str]
    viewer_url: str | None = None

    def wait(self, timeout: float = 60.0) -> int:
        return self.popen.wait(timeout=timeout)

    def stop(self) -> None:
        """Killed if still running, its output pipe closed."""
        if self.popen.poll() is None:
            self.popen.kill()
            self.popen.wait(timeout=10)
        if self.popen.stdout is not None:
            self.popen.stdout.close()


def typed_verbs(cls: type) -> dict[str, list[str]]:
    """Each verb that ``cls`` (``Client`` or ``AsyncClient``) has a typed method for, and
    those methods (the ones tagged ``@speaks(verb)``); any other verb is ``robot.VERB(*words)``."""
    found: dict[str, list[str]] = {}
    for name, member in inspect.getmembers(cls, callable):
        verb = getattr(member, "__c2rviz_verb__", None)
        if verb is not None:
            found.setdefault(verb, []).append(name)
    return found


def start_program(*args: str, timeout: float = 120.0, default_crcl_port: bool = False) -> Process:
    """Start ``python -m c2rviz --port 0 ARGS`` (``--no-rosbridge`` too, unless ARGS name
    ``--rosbridge-port``, and ``--crcl-port 0`` unless they name CRCL's or ask for its
    ``default_crcl_port``); wait until it listens (the ``c2rviz_process`` fixture's)."""
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
    return Process(popen, port, output, url)
