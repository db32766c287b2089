"""A real c2rviz server in the test process: ``TestServer``.

It is the program's own wiring (``app.config`` settings, ``app.members`` robots, a
``World`` on the chosen clock, ``Services``, a ``CommandServer`` per robot, the page and
the other doors if asked) on an asyncio loop in a thread of its own, on free ports. A
controller's test talks to it over TCP like to any c2rviz, with ``c2rviz.Client``.

Robots are loaded once per set of options and kept for the next server (loading a URDF
is most of a start); each server has a world of its own, so nothing a test does reaches
the next one.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .. import CommandServer  # the package's lazy name follows the text door's home
from ..app.config import Settings, find_ini, load_settings
from ..app.doors import Opened, close_doors, open_doors
from ..app.members import Member, furnish, members
from ..app.program import write_page
from ..observers.recorder import Recorded
from ..session.services import Services
from ..session.session import Session
from ..world.clock import Hold
from ..world.clocks import parse_clock
from ..world.effects import NullScene, Scene
from ..world.state import RobotState
from ..world.world import World

__all__ = ["RUNTIME_OPTIONS", "TestServer"]

T = TypeVar("T")

RUNTIME_OPTIONS = (
    "clock",
    "viewer",
    "doors",
    "record",
    "motion",
    "speed",
    "guard",
    "lspeed",
    "faults",
)
"""Options that do not change which robots are loaded (the rest key the robot cache)."""
_START_TIMEOUT_S = 120.0
_loaded: dict[str, tuple[list[Member], str | None]] = {}
_in_use: set[str] = set()


def _settings(options: Mapping[str, Any]) -> Settings:
    """The program's settings for ``options``: flag names as keys (``robot``, ``cell``,
    ``ini``, ``clock``, ``motion``, ``max_objects``...), every port free, no page unless
    ``viewer=True``."""
    given = {k: v for k, v in options.items() if k not in ("ini", "doors", "record", "faults")}
    ports = {name: 0 for name in Settings.__dataclass_fields__ if name.endswith("port")}
    overrides: dict[str, Any] = {**ports, "viewer": False, **given}
    overrides["robot_flag"] = "robot" in given
    overrides["urdf_flag"] = "urdf" in given
    return load_settings(find_ini(options.get("ini")), overrides)


class TestServer:
    """One running server; see the module docstring.

    Attributes:
        settings: What it was started with.
        host: Its address (127.0.0.1).
        ports: Each robot's command port, by name (the first is ``port``).
        world, services: Its state (use them through ``call``: they live on its loop).
        viewer_url: The page's address (None: no page).
    """

    __test__ = False  # not a test class, whatever pytest thinks of the name

    def __init__(self, options: Mapping[str, Any]) -> None:
        """Load the robots (or take them from the cache); ``start`` serves them."""
        self.options = dict(options)
        self.settings = _settings(self.options)
        parse_clock(self.settings.clock)  # a bad clock says so here
        key = repr(sorted((k, v) for k, v in options.items() if k not in RUNTIME_OPTIONS))
        self._key: str | None = None  # the cache entry this server uses (one server at a time)
        if key in _in_use or key not in _loaded:
            loaded = members(self.settings)
            _loaded.setdefault(key, loaded)
        if key not in _in_use:
            loaded = _loaded[key]
            self._key = key
            _in_use.add(key)
        self.members = [dataclasses.replace(m, port=0) for m in loaded[0]]
        self.cell = loaded[1]
        self.host = self.settings.host
        self.ports: dict[str, int] = {}
        self.viewer_url: str | None = None
        self.quit_requested = threading.Event()
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._keep_page = False
        self._servers: list[CommandServer] = []
        self._thread = threading.Thread(target=self._run, name="c2rviz-test-server", daemon=True)

    @property
    def port(self) -> int:
        """The first robot's command port."""
        return next(iter(self.ports.values()))

    @property
    def robot(self) -> str:
        """The first robot's name."""
        return self.members[0].name

    def start(self) -> TestServer:
        """Serve; return once every port listens.

        Raises:
            C2rvizError, OSError: the program could not start (as ``c2rviz`` would say).
        """
        self._thread.start()
        if not self._ready.wait(_START_TIMEOUT_S):
            raise RuntimeError(f"the c2rviz server did not start in {_START_TIMEOUT_S:g} s")
        if self._error is not None:
            self._thread.join(timeout=10)
            raise self._error
        return self

    def call(self, fn: Callable[..., T], *args: Any) -> T:
        """Run ``fn(*args)`` on the server's loop (where its world lives); return its result."""
        assert self._loop is not None

        async def run() -> T:
            return fn(*args)

        return asyncio.run_coroutine_threadsafe(run(), self._loop).result(60)

    def now(self) -> float:
        """The server's clock [s]."""
        return self.call(lambda: self.world.clock.now())

    def run(self, line: str, robot: str | None = None) -> str:
        """Run one command line as a session of its own (source ``test``); return its reply
        text (``error: ...`` too), awaited if it waits (meanwhile the test's idle clients
        wait for nothing: ``idle_clients``)."""

        async def ask() -> str:
            session = Session(self.services, "test", robot)
            try:
                reply = session.run(line)
                return "" if reply is None else reply if isinstance(reply, str) else await reply
            except Exception as exc:  # a C2rvizError: its error reply, as a door would send
                return f"error: {exc}"

        assert self._loop is not None
        with self.idle_clients():
            return asyncio.run_coroutine_threadsafe(ask(), self._loop).result(_START_TIMEOUT_S)

    @contextlib.contextmanager
    def idle_clients(self) -> Iterator[None]:
        """Inside, the clients connected now that have no command running wait for nothing.

        A virtual clock stands still while any client is busy, and a connected client with
        nothing to wait for counts as busy (it may be about to send). A test thread that
        drives two clients blocks on one while the other sits idle: wrap that in this, e.g.
        ``with c2rviz_server.idle_clients(): other.stop()``. A client that sends a line
        inside is busy again as usual.
        """
        released = self.call(self._release_idle)
        try:
            yield
        finally:
            self.call(self._take_back, released)

    def _take_back(self, released: list[Hold]) -> None:
        still = {id(c.hold) for server in self._servers for c in server.connections}
        for hold in released:
            if id(hold) in still:
                hold.take()

    def _release_idle(self) -> list[Hold]:
        idle = [c.hold for server in self._servers for c in server.connections if not c.waiting]
        for hold in idle:
            hold.release()
        return idle

    def keep_page(self, keep: bool) -> None:
        """Whether a recording stopped from now on also writes its page (NAME.html)."""
        self._keep_page = keep

    def stop(self) -> None:
        """Stop serving (every client is answered and closed), free the ports."""
        if self._loop is not None and self._stop is not None and self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(timeout=60)
        if self._key is not None:
            _in_use.discard(self._key)
            self._key = None

    # The server's thread.

    def _run(self) -> None:
        try:
            asyncio.run(self._serve())
        except BaseException as exc:  # handed to start(), which re-raises it
            self._error = exc
            self._ready.set()

    def _page(self, recorded: Recorded, state: RobotState) -> Path:
        """NAME.html, for a recording that is kept (a failed test's); else a note of a line."""
        if self._keep_page:
            return write_page(recorded, state)
        placeholder = recorded.csv.with_suffix(".html")
        placeholder.write_text("<p>Not kept: the test passed.</p>\n")
        return placeholder

    async def _serve(self) -> None:
        settings = self.settings
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        world = World(
            {m.name: m.robot for m in self.members},
            clock=parse_clock(settings.clock),
            hz=settings.hz,
            origins={m.name: m.origin for m in self.members},
            limits={m.name: m.limits for m in self.members},
            max_objects=settings.max_objects,
        )
        self.world = world
        self.services = Services(
            world,
            limits=settings.limits,
            defaults=settings.session,
            rng=np.random.default_rng(settings.session.plan_seed),  # as the program: --seed
            record_dir=settings.record_dir,
            trail_points=settings.trail_points,
            exporters=(self._page,),
        )
        for member in self.members:
            furnish(world, member)
        for line in self.options.get("faults", ()):  # `fault` lines on the first robot, at start
            Session(self.services, "test", self.members[0].name).run(f"fault {line}")
        servers = self._servers
        doors: Sequence[Opened] = []
        scene: Scene = NullScene()
        try:
            for member in self.members:
                server = CommandServer(self.services, on_quit=self._quit, robot=member.name)
                _, port = await server.start(settings.host, 0)
                world.state(member.name).port = self.ports[member.name] = port
                servers.append(server)
            if self.options.get("doors"):
                doors = await open_doors(settings, self.services, self.members, self._quit)
            if settings.viewer:
                scene = self._open_viewer()
                world.add_observers([scene])
                scene.start(self._loop)
                self.viewer_url = scene.url
            self._ready.set()
            await self._stop.wait()
        finally:
            for member in self.members:  # a recording still running is finished, as at exit
                reply = Session(self.services, "test", member.name).run("record")
                if isinstance(reply, str) and reply.startswith("ok recording"):
                    stopped = Session(self.services, "test", member.name).run("record stop")
                    if stopped is not None and not isinstance(stopped, str):
                        await stopped
            await close_doors(doors)
            for server in servers:
                await server.stop()
            self.services.close()
            scene.stop()

    def _quit(self) -> None:
        self.quit_requested.set()
        if self._stop is not None:
            self._stop.set()

    def _open_viewer(self) -> Scene:
        from ..view.policy import DoorPolicy
        from ..view.viser_scene import ViserScene

        settings = self.settings
        policy = DoorPolicy(settings.viewer_origins, settings.viewer_token, settings.max_viewers)
        return ViserScene(
            self.services,
            settings.viewer_host,
            settings.viewer_port,
            settings.hz,
            policy=policy,
            title=self.cell,
        )
