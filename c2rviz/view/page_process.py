"""The page process (``--page-process``): viser, the scene and the tabs, off the command loop.

Forked by the program at start (``page_start.fork``, which calls ``run``), or started by
``page_link.PageLink`` after a crash as ``python -m c2rviz.view.page_process FD``, FD
being its end of the channel (``page_channel``). It reads a ``Hello`` (``page_snapshot``),
builds a mirror of the world from it (``MirrorWorld``: the same robots, placed and
posed as they are, fed by the frames that follow, never moving on its own), and serves
the page with the usual ``ViserScene`` over it: the same door, origin check, token and
limits, the same panel, plots and handles. A page's control runs a line on its robot's
``ForwardingSession``, which hands it back over the channel to the command process,
where it runs on the page's real ``Session``. The frames then bring what it did.

It stops when told (``stop``), when the channel ends (the command process is gone), or
on SIGTERM/SIGINT.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import pickle
import signal
import socket
import sys
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, PathCollides
from ..session.services import Services
from ..session.session import Reply, Session
from ..world.state import Marker
from .door_rules import DoorPolicy
from .page_channel import FrameReader, encode
from .page_frame import MirrorClock, MirrorWorld, _Path
from .page_snapshot import Hello, MirrorCell, Snapshot
from .viser_scene import ViserScene

log = logging.getLogger("c2rviz.view")

REST_PER_WORK = 0.25
"""The page's sends leave its loop this much time per second of work (the program's
page leaves 1.0, ``scene_send.REST_PER_WORK``, for its clients' lines): here the loop
serves no client, only the channel, whose frames wait in the socket meanwhile."""
SLICE_S = 0.03
"""The longest slice of a send here [s] (the program's page: ``scene_send.SLICE_S``):
a frame of 64 robots in one or two atomic batches, not a dozen (each batch's end wakes
viser's thread, which takes the GIL to encode a window of the batch)."""


class ForwardingSession(Session):
    """The page's session of one robot in the page process: its lines go to the command
    process (``send``), which runs them on its own page session."""

    def __init__(self, services: Services, robot: str, send: Callable[[list[Any]], None]) -> None:
        """The page's session of ``robot``; ``send(message)`` puts a message on the channel."""
        super().__init__(services, source="page", robot=robot)
        self.send = send
        self.set_degrees(True)

    def run(self, line: str) -> Reply | None:
        """Hand ``line`` on; what it will do is assumed meanwhile (a slider's target, the
        speed), so the page answers its tabs at once; the next frame says the truth."""
        self.send(["line", self.state.name, line])
        words = line.split()
        with contextlib.suppress(ValueError, IndexError, C2rvizError):
            if words[0] == "speed":
                self.set_speed(float(words[1]))
            elif words[0] == "move" and len(words) == 3:  # the page's slider: move I V
                index = int(words[1])
                value = self.to_si([index], [float(words[2])])[0]
                target = list(self.state.target)
                target[index] = value
                self.state.target = tuple(target)
        return None


class PageProcess:
    """The page process's state: the mirror, the scene, the channel."""

    def __init__(self, hello: Hello, writer: asyncio.StreamWriter) -> None:
        config, snap = hello.config, hello.snapshot
        self.writer = writer
        self.world = world = MirrorWorld(snap, config.hz)
        self.services = Services(world, defaults=config.defaults, trail_points=config.trail_points)
        world.observers = []  # drop what Services added (guards): the page only draws
        self.services.watch.origin = snap.watch_origin
        self.cell = MirrorCell(world)
        for name, r in snap.robots.items():
            self.cell.objects(name, r.objects)
        self._clears: dict[str, int] = {}  # each trail's clears, as last told
        policy = DoorPolicy(config.origins, config.token, config.max_viewers)
        self.scene = ViserScene(
            self.services,
            config.host,
            config.port,
            config.hz,
            policy=policy,
            title=config.title,
            page_session=lambda services, robot: ForwardingSession(services, robot, self.send),
            lighting=config.lighting,
        )
        self.scene.scheduler.rest_per_work = REST_PER_WORK
        self.scene.slice_s = SLICE_S
        world.add_observers([self.scene])
        self.apply_state(snap, fresh=True)

    def send(self, message: list[Any]) -> None:
        if not self.writer.is_closing():
            self.writer.write(encode(message))

    # what the command process says

    def apply(self, message: list[Any]) -> bool:
        """Apply one message; False: stop."""
        kind = message[0]
        if kind == "frame":
            self.apply_frame(message[1], message[2], message[3])
            self.send(["applied"])  # the program's next frame waits for this word
        elif kind == "state":
            self.apply_state(pickle.loads(message[1]), fresh=False)
        elif kind == "stop":
            return False
        return True

    def apply_state(self, snap: Snapshot, fresh: bool) -> None:
        world, scene = self.world, self.scene
        assert isinstance(world.clock, MirrorClock)
        world.clock.heard(snap.t)
        for name, r in snap.robots.items():
            state = world.robots[name]
            if not fresh:
                state.markers.clear()
                scene.on_clear_markers(name)
                for marker in r.markers:
                    state.markers.append(marker)
                    scene.on_marker(name, marker)
                state.tool, state.ghost = r.tool, r.ghost
                scene.on_tool(name, r.tool)
                scene.on_ghost(name, r.ghost)
            state.target = r.target
            world.moved(name, r.moving, r.seconds_left)
            self.sessions_speed(name, r.speed)
            world._show(state, r.q, snap.t)
            world._show_opening(state, r.opening, snap.t)
            self.objects(name, r.objects)
            scene.on_collisions(name, r.collisions)
            scene.show_faults(name, snap.banners.get(name, ""))
        self.trails(snap.trails)
        scene.on_clients(snap.clients)
        for line, accepted in reversed(snap.commands):
            scene.on_command("", line, accepted)
        scene.on_parts(self.cell.parts(snap.parts), snap.t)
        scene.on_goals(self.cell.set_goals(snap.goals))
        scene.on_cameras(self.cell.cameras(snap.cameras))

    def objects(self, name: str, objects: Sequence[Any]) -> None:
        self.world.objects[name] = list(objects)
        self.cell.objects(name, objects)
        self.scene.on_objects(name, objects)

    def sessions_speed(self, name: str, speed: float) -> None:
        session = self.scene.sessions.get(name)
        if session is not None:
            session.set_speed(speed)

    def apply_frame(self, t: float, robots: list[Any], events: list[Any]) -> None:
        world, scene = self.world, self.scene
        assert isinstance(world.clock, MirrorClock)
        world.clock.heard(t)
        for name, samples, opening, target, moving, seconds_left, speed in robots:
            state = world.robots.get(name)
            if state is None:
                continue
            state.target = tuple(target)
            world.moved(name, moving, seconds_left)
            self.sessions_speed(name, speed)
            for sample in samples:
                world._show(state, tuple(sample[1:]), sample[0])
            if opening != state.opening:
                world._show_opening(state, opening, t)
            scene.redraw(name)
        for event in events:
            self.apply_event(event)

    def apply_event(self, event: list[Any]) -> None:
        world, scene = self.world, self.scene
        kind = event[0]
        if kind == "marker":
            _, name, position, wxyz, rgb, shape = event
            marker = Marker(tuple(position), tuple(wxyz), tuple(rgb), shape)
            world.robots[name].markers.append(marker)
            scene.on_marker(name, marker)
        elif kind == "clear":
            world.robots[event[1]].markers.clear()
            scene.on_clear_markers(event[1])
        elif kind == "clients":
            scene.on_clients(event[1])
        elif kind == "commands":  # the newest first, as many as the readout keeps
            for line, accepted in reversed(event[1]):
                scene.on_command("", line, accepted)
        elif kind == "tool":
            tool = pin.SE3(np.array(event[2], dtype=float).reshape(4, 4))
            world.robots[event[1]].tool = tool
            scene.on_tool(event[1], tool)
        elif kind == "objects":
            self.objects(event[1], pickle.loads(event[2]))
        elif kind == "collisions":
            scene.on_collisions(event[1], [(a, b) for a, b in event[2]])
        elif kind == "refused":
            _, name, source, line, text, pair, target = event
            scene.on_refused(name, source, line, _error(text, pair, target))
        elif kind == "ghost":
            world.robots[event[1]].ghost = event[2]
            scene.on_ghost(event[1], event[2])
        elif kind == "trails":
            self.trails(event[1])
        elif kind == "parts":
            scene.on_parts(self.cell.parts(event[1]), event[2])
        elif kind == "goals":
            scene.on_goals(self.cell.set_goals(event[1]))
        elif kind == "cameras":
            scene.on_cameras(self.cell.cameras(event[1]))
        elif kind == "fault":
            scene.show_faults(event[1], event[2])
        elif kind == "path":
            travel = world.travels.by_robot[event[1]]
            travel.path = None if event[2] is None else _Path(event[2])  # type: ignore[assignment]
            scene.redraw(event[1])

    def trails(self, on: Sequence[Sequence[Any]]) -> None:
        """The trails on are ``on``: [name, clears] each (a trail whose clears moved
        was cleared: the page's is cleared too, from where its arm is now)."""
        keeper, clears = self.services.trails, dict((name, n) for name, n in on)
        for name in set(keeper.trails) - set(clears):
            keeper.stop(name)
        for name, n in clears.items():
            if name not in self.world.robots:
                continue
            if name not in keeper.trails:
                keeper.start(name)
            elif self._clears.get(name, n) != n:
                keeper.clear(name)
        self._clears = clears


def _error(text: str, pair: list[str] | None, target: list[float] | None) -> C2rvizError:
    """A refusal as the command process told it (a guard's keeps its pair and target)."""
    if pair is None:
        return C2rvizError(text)
    error = PathCollides(pair[0], pair[1], 1.0, True, target)
    error.args = (text,)
    return error


async def serve(sock: socket.socket) -> int:
    """Serve the page until told to stop or the channel ends; the exit status."""
    loop = asyncio.get_running_loop()
    reader, writer = await asyncio.open_connection(sock=sock)
    frames = FrameReader()
    stop = asyncio.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)
    page: PageProcess | None = None
    pending: list[list[Any]] = []
    reading = asyncio.ensure_future(reader.read(1 << 16))
    stopping = asyncio.ensure_future(stop.wait())
    try:
        while True:
            done, _ = await asyncio.wait({reading, stopping}, return_when=asyncio.FIRST_COMPLETED)
            if stopping in done:
                return 0
            data = reading.result()
            if not data:
                return 0
            pending += frames.feed(data)
            reading = asyncio.ensure_future(reader.read(1 << 16))
            while pending:
                message = pending.pop(0)
                if page is None:
                    if message[0] != "hello":
                        continue
                    hello = pickle.loads(message[1])
                    logging.getLogger().setLevel(hello.config.log_level)
                    try:
                        page = PageProcess(hello, writer)
                    except OSError as exc:
                        writer.write(encode(["error", exc.errno or 0, str(exc.strerror or exc)]))
                        await writer.drain()
                        return 1
                    page.scene.start(loop)
                    writer.write(encode(["ready", page.scene.port, page.scene.url or ""]))
                elif not page.apply(message):
                    return 0
    finally:
        reading.cancel()
        stopping.cancel()
        if page is not None:
            page.scene.stop()
        writer.close()


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m c2rviz.view.page_process FD``: serve the page over channel FD."""
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 1 or not args[0].isdigit():
        print("usage: python -m c2rviz.view.page_process FD (started by c2rviz)", file=sys.stderr)
        return 2
    logging.basicConfig(level=logging.WARNING, format="c2rviz: %(levelname)s: %(message)s")
    return run(socket.socket(fileno=int(args[0])))


def run(sock: socket.socket) -> int:
    """Serve the page over channel ``sock`` until told to stop or it ends; the exit status
    (``main``'s, or that of the page process the program forked, ``page_start.fork``)."""
    try:
        return asyncio.run(serve(sock))
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
