"""A real c2rviz server in the test process: ``TestServer``.

It is the program's own wiring (``app.config`` settings, ``app.members`` robots, a
``World`` on the chosen clock, ``Services``, a ``CommandServer`` per robot, the page and
the other doors if asked) on an asyncio loop in a thread of its own, on free ports. A
controller's test talks to it over TCP like to any c2rviz, with ``c2rviz.Client``; the
CRCL and rosbridge doors, when asked (``crcl=True``, ``rosbridge=True``, ``doors=True``),
say their free ports (``crcl_port``, ``rosbridge_port``).

A test that built its own robots (``Robot`` objects, not the ini's) passes them as
``robots=`` (no ini is read then, unless ``ini`` is given), and may add observers of its
own (``observers=``) and give a clock object (``clock=VirtualClock()``) or the server's
limits (``limits=ServerLimits(...)``) among the options: c2rviz's own tests do.

Robots are loaded once per set of options and kept for the next server (loading a URDF
is most of a start); each server has a world of its own, so nothing a test does reaches
the next one.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import Callable, Coroutine, Iterator, Mapping, Sequence
from concurrent.futures import Future
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from .. import CommandServer  # the package's lazy name follows the text door's home
from ..app.doors import Opened, close_doors, open_doors
from ..app.ini_world import ini_cameras, place_cameras
from ..app.members import furnish
from ..app.program import write_page
from ..observers.recorded import Recorded
from ..robot.model import Robot
from ..session.services import Services
from ..session.session import Session
from ..world.clock import Clock, Hold
from ..world.observer import NullScene, Observer, Scene
from ..world.state import RobotState
from ..world.virtual_clock import parse_clock
from ..world.world import World
from .options import give_back, given_members, settings_for, take_members

T = TypeVar("T")
_START_TIMEOUT_S = 120.0


class TestServer:
    """One running server; see the module docstring.

    Attributes:
        settings: What it was started with.
        host: Its address (127.0.0.1).
        ports: Each robot's command port, by name (the first is ``port``).
        world, services: Its state (use them through ``call``: they live on its loop).
        viewer_url: The page's address (None: no page).
        crcl_ports: Each robot's CRCL port, by name, when the CRCL door is open (the
            first is ``crcl_port``).
        rosbridge_port: The rosbridge websocket's port (None: no rosbridge door).
    """

    __test__ = False  # not a test class, whatever pytest thinks of the name

    def __init__(
        self,
        options: Mapping[str, Any] | None = None,
        *,
        robots: Robot | Mapping[str, Robot] | None = None,
        observers: Sequence[Observer] = (),
        held: bool = False,
    ) -> None:
        """Load the robots (or take them from the cache, or ``robots``); ``start`` serves
        them, each world telling ``observers`` too. ``held``: a virtual clock stands still
        from the start until ``begin`` (the plugin's servers: a fault the marker schedules
        ``after 6`` comes 6 s into the test, not before its first line)."""
        self._held = held
        self._start_hold: Hold | None = None
        self.options = dict(options or {})
        self.settings = settings_for(self.options, read_ini=robots is None)
        clock = self.options.get("clock")
        self._clock = clock if isinstance(clock, Clock) else parse_clock(self.settings.clock)
        self._observers = list(observers)
        self._key: str | None = None  # the cache entry this server uses (one server at a time)
        if robots is not None:
            self.members, self.cell = given_members(robots), None
        else:
            self.members, self.cell, self._key = take_members(self.options, self.settings)
        self._as_program = robots is None  # given robots: their URDF's limits, no ports told
        self.host = self.settings.host
        self.ports: dict[str, int] = {}
        self.crcl_ports: dict[str, int] = {}
        self.rosbridge_port: int | None = None
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
    def crcl_port(self) -> int:
        """The first robot's CRCL port (asked with ``crcl=True`` or ``doors=True``)."""
        if not self.crcl_ports:
            raise RuntimeError("no CRCL door: ask for one with crcl=True (or doors=True)")
        return next(iter(self.crcl_ports.values()))

    @property
    def loop(self) -> asyncio.AbstractEventLoop:
        """The server's event loop (its world and services live there)."""
        assert self._loop is not None, "start() first"
        return self._loop

    @property
    def thread(self) -> threading.Thread:
        """The thread the server runs in."""
        return self._thread

    @property
    def command_servers(self) -> list[CommandServer]:
        """Each robot's text door, in the order of ``ports``."""
        return self._servers

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
        done: Future[T] = Future()

        def run() -> None:  # a plain callback: no task, one turn of the loop
            try:
                done.set_result(fn(*args))
            except BaseException as exc:  # handed to the caller
                done.set_exception(exc)

        self.loop.call_soon_threadsafe(run)
        return done.result(60)

    def call_async(self, coro: Coroutine[Any, Any, T]) -> T:
        """Run ``coro`` on the server's loop; return its result."""
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(60)

    def begin(self) -> None:
        """The test begins: a ``held`` server's clock runs from now on (again: nothing)."""
        self.call(self._let_go)

    def _let_go(self) -> None:
        hold, self._start_hold = self._start_hold, None
        if hold is not None:
            hold.close()

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
                if reply is None or isinstance(reply, str):
                    return reply or ""
                self._let_go()  # a reply that waits on the clock: the clock must run
                return await reply
            except Exception as exc:  # a C2rvizError: its error reply, as a door would send
                return f"error: {exc}"

        assert self._loop is not None
        with self.idle_clients():
            return asyncio.run_coroutine_threadsafe(ask(), self._loop).result(_START_TIMEOUT_S)

    def text_clients(self) -> int:
        """How many clients the text ports serve now (counted on the server's loop)."""
        return self.call(lambda: sum(len(server.connections) for server in self._servers))

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
            # The server may be ending on its own (a client's ``quit``): its loop can close
            # between the check above and this call, and then there is nothing to stop.
            with contextlib.suppress(RuntimeError):
                self._loop.call_soon_threadsafe(self._stop.set)
        self._thread.join(timeout=60)
        give_back(self._key)
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
            clock=self._clock,
            hz=settings.hz,
            origins={m.name: m.origin for m in self.members},
            limits={m.name: m.limits for m in self.members} if self._as_program else None,
            max_objects=settings.max_objects,
        )
        world.add_observers(self._observers)
        self.world = world
        if self._held:
            self._start_hold = world.clock.hold()
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
        place_cameras(world, self.services.rng, ini_cameras(settings.ini))  # as the program
        for line in self.options.get("faults", ()):  # `fault` lines on the first robot, at start
            Session(self.services, "test", self.members[0].name).run(f"fault {line}")
        servers = self._servers
        doors: Sequence[Opened] = []
        scene: Scene = NullScene()
        try:
            for member in self.members:
                server = CommandServer(self.services, on_quit=self._quit, robot=member.name)
                _, port = await server.start(settings.host, 0)
                self.ports[member.name] = port
                if self._as_program:  # (robots a test built: the world as it built it)
                    world.state(member.name).port = port
                servers.append(server)
            if settings.crcl or settings.rosbridge:
                doors = await open_doors(settings, self.services, self.members, self._quit)
                self._door_ports(doors)
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

    def _door_ports(self, doors: Sequence[Opened]) -> None:
        from ..app.doors import RosbridgeDoor
        from ..transports.crcl.server import CrclServer

        for opened in doors:
            door = opened.door
            if isinstance(door, CrclServer) and door.address is not None:
                self.crcl_ports[door.robot or self.robot] = door.address[1]
            elif isinstance(door, RosbridgeDoor):
                self.rosbridge_port = door.port

    def _quit(self) -> None:
        self.quit_requested.set()
        if self._stop is not None:
            self._stop.set()

    def _open_viewer(self) -> Scene:
        from ..view.door_rules import DoorPolicy
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
            lighting=settings.viewer_lighting,
        )
