"""A real c2rviz server for rosbridge tests: the world, its services, the text port and the
rosbridge door, wired as the program wires them, on one event loop in a thread.

``WorldServer`` starts everything on 127.0.0.1 port 0. Tests talk to it as clients
would: roslibpy (its asyncio transport), a raw websockets client, and the text port
through ``support.Client``. ``Notes`` is an observer that keeps the world's commands
with the clock time each was noted (a trajectory starts at its note's time). The
helpers subscribe with roslibpy, call the command service and compose TF.
"""

from __future__ import annotations

import asyncio
import queue
import threading
import time
from collections.abc import Callable, Coroutine, Mapping, Sequence
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
import roslibpy
from support import Client

from c2rviz.app.config import Settings
from c2rviz.app.doors import RosbridgeDoor
from c2rviz.robot.model import Robot
from c2rviz.session import Services
from c2rviz.transports.rosbridge import COMMAND_SERVICE_TYPE
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.world.clock import Clock
from c2rviz.world.observer import Observer
from c2rviz.world.world import World

WAIT_S = 20.0  # generous: the machine is shared; a passing test never waits this long


def listen(ros: roslibpy.Ros, topic: str, kind: str) -> queue.Queue[dict[str, Any]]:
    """Subscribe and return the queue its messages land in."""
    received: queue.Queue[dict[str, Any]] = queue.Queue()
    roslibpy.Topic(ros, topic, kind).subscribe(received.put)
    return received


def until(
    received: queue.Queue[dict[str, Any]], wanted: Callable[[dict[str, Any]], bool]
) -> dict[str, Any]:
    """The first message that is ``wanted`` (others are skipped)."""
    deadline = time.monotonic() + WAIT_S
    while True:
        msg = received.get(timeout=max(0.01, deadline - time.monotonic()))
        if wanted(msg):
            return msg


def seconds(stamp: dict[str, int]) -> float:
    return stamp["sec"] + stamp["nanosec"] * 1e-9


def text_client(server: WorldServer, robot: str = "motoman_sia20d") -> Client:
    return Client("127.0.0.1", server.ports[robot], timeout=WAIT_S)


def command_service(ros: roslibpy.Ros, name: str = "/c2rviz/command") -> roslibpy.Service:
    return roslibpy.Service(ros, name, COMMAND_SERVICE_TYPE)


def ask(service: roslibpy.Service, line: str) -> dict[str, Any]:
    return service.call(roslibpy.ServiceRequest({"command": line}), timeout=WAIT_S)


def tf_tree(*messages: dict[str, Any]) -> dict[str, tuple[str, pin.SE3]]:
    """child frame -> (parent frame, placement) from TFMessages (later ones win)."""
    tree = {}
    for msg in messages:
        for item in msg["transforms"]:
            t, r = item["transform"]["translation"], item["transform"]["rotation"]
            xyzquat = np.array([t["x"], t["y"], t["z"], r["x"], r["y"], r["z"], r["w"]])
            tree[item["child_frame_id"]] = (item["header"]["frame_id"], pin.XYZQUATToSE3(xyzquat))
    return tree


def in_root(tree: dict[str, tuple[str, pin.SE3]], frame: str) -> tuple[str, pin.SE3]:
    """The root of ``frame``'s tree, and ``frame``'s placement in it."""
    placement = pin.SE3.Identity()
    while frame in tree:
        parent, step = tree[frame]
        placement = step * placement
        frame = parent
    return frame, placement


@dataclass(frozen=True)
class Note:
    """One command the world was told of, and the clock time [s] it was told."""

    t: float
    source: str
    line: str
    accepted: bool


class Notes(Observer):
    """Keeps every command the world is told of (``on_command``) with its clock time."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.notes: list[Note] = []

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.notes.append(Note(self.world.clock.now(), source, line, accepted))


class WorldServer:
    """The world, a text port per robot and the rosbridge door, on a loop in a thread."""

    def __init__(
        self,
        robots: Mapping[str, Robot],
        *,
        cell: bool = False,
        origins: Mapping[str, pin.SE3] | None = None,
        settings: Settings | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.clock = clock
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.quit = threading.Event()
        self.settings = settings or Settings(cell="test" if cell else None)
        self.run(self._start(robots, origins))

    async def _start(
        self, robots: Mapping[str, Robot], origins: Mapping[str, pin.SE3] | None
    ) -> None:
        self.world = World(dict(robots), origins=origins, clock=self.clock)
        self.notes = Notes(self.world)
        self.world.add_observers([self.notes])
        self.services = Services(self.world)
        self.ports: dict[str, int] = {}
        self.text_servers: list[CommandServer] = []
        for name in robots:
            server = CommandServer(self.services, on_quit=self.quit.set, robot=name)
            _, self.ports[name] = await server.start("127.0.0.1", 0)
            self.text_servers.append(server)
        self.door = RosbridgeDoor(self.services, self.settings, self.quit.set)
        await self.door.start("127.0.0.1", 0)
        self.port = self.door.port
        self.url = self.door.url

    def run(self, coroutine: Coroutine[Any, Any, Any]) -> Any:
        """Run ``coroutine`` on the server's loop and return its result."""
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(WAIT_S)

    def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        """Call ``fn(*args)`` on the server's loop and return its result."""
        done: Future[Any] = Future()

        def call() -> None:
            try:
                done.set_result(fn(*args))
            except BaseException as error:
                done.set_exception(error)

        self.loop.call_soon_threadsafe(call)
        return done.result(WAIT_S)

    def q(self, robot: str | None = None) -> tuple[float, ...]:
        """The robot's joints as shown now [rad or m]."""
        return self.call(lambda: self.world.state(robot).q)

    def notes_of(self, prefix: str) -> Sequence[Note]:
        """The notes whose line starts with ``prefix``."""
        return self.call(lambda: [n for n in self.notes.notes if n.line.startswith(prefix)])

    def stop(self) -> None:
        async def stop() -> None:
            await self.door.stop()
            for server in self.text_servers:
                await server.stop()
            self.services.close()

        self.run(stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(WAIT_S)
        self.loop.close()
