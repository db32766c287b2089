"""The page in a process of its own (``--page-process``): the command process's side.

``PageLink`` is the scene the world tells its effects to. It draws nothing: it notes
what changed (``page_frame.FrameNotes``: every joint sample of every robot, markers,
objects, collisions, the tool, the ghost, refusals, the clients and the last commands,
the parts, goals, cameras and fault banners) and, at most once per frame (``1/hz``),
publishes one ``frame`` message on the channel (``page_channel``) to the page process
(``page_process``), which owns viser, builds the scene and serves the tabs. So the
command loop does only I/O and bookkeeping: a frame costs it one msgpack encoding and
one socket write, whatever the number of tabs.

The first page process is the one the program forked at start (``page_start.fork``);
a later one is spawned fresh (``python -m c2rviz.view.page_process``, so it inherits
neither the loop nor its threads). Each is handed a ``hello``: how to serve the page
(host, port, hz, the door's policy) and a snapshot of the world (``page_snapshot``).
Input from the page (sliders, handles, buttons) comes back as ``line`` messages and
runs on the page's ``Session`` of that robot, like any other door's lines. When the
page process exits or crashes, the link logs it and starts another on the same port
(tabs reconnect by themselves) with a fresh snapshot; commands go on meanwhile. While
the page falls behind (its socket's buffer past ``BACKLOG``) frames are dropped and a
snapshot follows once it catches up. At most ``IN_FLIGHT`` frames go unapplied: a page
process short of CPU says ``applied`` less often and gets fewer, fuller frames.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import pickle
import subprocess
import time
from collections import deque
from collections.abc import Awaitable
from typing import Any

from ..errors import C2rvizError, MotionInterrupted
from ..session.services import Services
from ..session.session import Session
from .door_rules import RateLimitedLog
from .page_channel import ChannelError, FrameReader, encode
from .page_frame import FrameNotes
from .page_snapshot import Hello, PageConfig, snapshot
from .page_start import PageProcessHandle, Spawned, spawn

log = logging.getLogger("c2rviz.view")

BACKLOG = 8 << 20
"""Bytes waiting for the page process past which frames are dropped (then a snapshot)."""
START_TIMEOUT_S = 60.0
"""Longest wait for the page process to serve the page [s]."""
STOP_TIMEOUT_S = 2.0
"""Longest wait for the page process to stop before it is killed [s]."""
IN_FLIGHT = 2
"""Frames written that the page process has not yet said it applied, past which the next
waits for its word (the notes gather meanwhile, so a page short of CPU gets fewer, fuller
frames instead of a queue of old ones at ``hz``)."""
RESTART_S = (0.2, 1.0, 5.0)
"""Pauses before starting the page process again after quick successive crashes [s]."""


class PageLink(FrameNotes):
    """The world's scene when the page runs in its own process; see the module docstring.

    Attributes:
        url: Where the page is served (None until the page process says).
        port: The page's port (None until then).
        sessions: The page's ``Session`` per robot (source ``page``).
        starts: Page processes started so far.
        frames: Frames published so far.
        process: The page process running now, if any.
    """

    def __init__(
        self, services: Services, config: PageConfig, spawned: Spawned | None = None
    ) -> None:
        """Set up; ``spawned``: a page process started early (``page_start``), to use first."""
        self._spawned = spawned
        world = services.world
        self.config = config
        self.url: str | None = None
        self.port: int | None = None
        self.starts = 0
        self.frames = 0
        self.process: PageProcessHandle | None = None
        sessions: dict[str, Session] = {}
        for name in world.robots:
            session = Session(services, source="page", robot=name)
            session.set_degrees(True)
            session.set_motion("off" if services.defaults.motion == "off" else "follow")
            sessions[name] = session
        super().__init__(services, sessions, config.recent_commands)
        self.request = self._request
        self._writer: asyncio.StreamWriter | None = None
        self._behind = False  # frames were dropped: a snapshot is due
        self._unapplied = 0  # frames written, not yet applied by the page process
        self._held = False  # a frame waits for the page process to apply one
        self._loop: asyncio.AbstractEventLoop | None = None
        self._flush: asyncio.TimerHandle | None = None
        self._last_flush = 0.0
        self._task: asyncio.Task[None] | None = None
        self._ready: asyncio.Future[str] | None = None
        self._stopping = False
        self._log = RateLimitedLog(log)

    # lifecycle

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Start the page process and keep one running until ``stop``."""
        self._loop = loop
        self._ready = loop.create_future()
        self._task = loop.create_task(self._supervise())

    async def opened(self) -> str:
        """The page's URL, once the first page process serves it.

        Raises:
            OSError: the page cannot be served (the page process's reason).
        """
        assert self._ready is not None, "start() first"
        try:
            return await asyncio.wait_for(asyncio.shield(self._ready), START_TIMEOUT_S)
        except asyncio.TimeoutError:
            raise OSError(
                0, f"the page process did not serve the page within {START_TIMEOUT_S:g} s"
            ) from None

    def stop(self) -> None:
        """Stop the page process (``STOP_TIMEOUT_S``, then killed); later calls do nothing."""
        if self._stopping:
            return
        self._stopping = True
        if self._flush is not None:
            self._flush.cancel()
        writer, self._writer = self._writer, None
        self.on_air = False
        if writer is not None:
            with contextlib.suppress(Exception):
                writer.write(encode(["stop"]))
                writer.close()
        if self._task is not None:
            self._task.cancel()
        process = self.process
        if process is not None:
            try:
                process.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=STOP_TIMEOUT_S)

    # the page process

    async def _supervise(self) -> None:
        crashes: deque[float] = deque(maxlen=len(RESTART_S))
        while not self._stopping:
            status = await self._run_once()
            if self._ready is not None and not self._ready.done():  # it never served
                self._fail(OSError(0, f"the page process ended at start (status {status})"))
                self._stopping = True
            if self._stopping:
                return
            now = time.monotonic()
            crashes.append(now)
            quick = sum(1 for t in crashes if now - t < 10.0)
            log.warning(
                "the page process stopped (status %s); starting it again (commands go on)",
                status,
            )
            await asyncio.sleep(RESTART_S[min(quick, len(RESTART_S)) - 1])

    async def _run_once(self) -> int | None:
        """Start one page process (or take the one started early), feed it until it ends;
        its exit status."""
        config = self.config
        if self.port is not None:  # again: where the tabs look
            config = config.again(self.port)
        if self._spawned is not None:
            (self.process, ours), self._spawned = self._spawned, None
        else:
            try:
                self.process, ours = spawn()
            except OSError as exc:
                self._fail(OSError(exc.errno, f"cannot start the page process: {exc.strerror}"))
                self._stopping = True
                return None
        self.starts += 1
        process = self.process
        reader, writer = await asyncio.open_connection(sock=ours)
        try:
            self._send_hello(writer, config)
            await self._read(reader)
        except (ChannelError, ConnectionError) as exc:
            log.warning("the page process's channel: %s", exc)
        finally:
            self._writer, self.on_air = None, False
            writer.close()
        while process.poll() is None and not self._stopping:
            await asyncio.sleep(0.02)
        return process.poll()

    def _send_hello(self, writer: asyncio.StreamWriter, config: PageConfig) -> None:
        hello = Hello(config, snapshot(self.services, self.sessions, self.commands))
        writer.write(encode(["hello", pickle.dumps(hello)]))
        self.fresh()
        self._behind = False
        self._unapplied, self._held = 0, False
        self._writer = writer

    async def _read(self, reader: asyncio.StreamReader) -> None:
        frames = FrameReader()
        while data := await reader.read(1 << 16):
            for message in frames.feed(data):
                self._heard(message)

    def _heard(self, message: list[Any]) -> None:
        """One message from the page process."""
        kind = message[0]
        if kind == "applied":
            self._unapplied = max(self._unapplied - 1, 0)
            if self._held:
                self._held = False
                self._request()
        elif kind == "line" and len(message) == 3:
            self._line(str(message[1]), str(message[2]))
        elif kind == "ready":
            self.port, self.url = int(message[1]), str(message[2])
            if self._ready is not None and not self._ready.done():
                self._ready.set_result(self.url)
        elif kind == "error":
            self._fail(OSError(int(message[1]), str(message[2])))
            self._stopping = True

    def _fail(self, exc: OSError) -> None:
        if self._ready is not None and not self._ready.done():
            self._ready.set_exception(exc)
        else:
            log.error("the page process: %s", exc.strerror or exc)

    # input from the page: a line on the page's session of that robot

    def _line(self, robot: str, line: str) -> None:
        session = self.sessions.get(robot)
        if session is None:
            return
        self._dirty.add(robot)  # the page learns the true target and speed
        self._request()
        try:
            reply = session.run(line)
        except C2rvizError as exc:
            self._log.warning("refused", f"refused from the page: {line}: {exc}")
            return
        if isinstance(reply, Awaitable):  # a reply that comes later: the page does not wait
            future = asyncio.ensure_future(reply)
            future.add_done_callback(functools.partial(self._answered, line))

    def _answered(self, line: str, future: asyncio.Future[Any]) -> None:
        error = None if future.cancelled() else future.exception()
        if isinstance(error, MotionInterrupted):
            return
        if isinstance(error, C2rvizError):
            self._log.warning("refused", f"refused from the page: {line}: {error}")
        elif error is not None:
            self._log.warning("failed", f"a page command failed: {line}: {error!r}")

    # publishing

    def _request(self) -> None:
        if self._flush is not None or self._loop is None or self._writer is None:
            return
        wait = self._last_flush + self.config.frame_s - time.perf_counter()
        self._flush = self._loop.call_later(max(wait, 0.0), self._publish)

    def _publish(self) -> None:
        """One ``frame`` message: each changed robot's samples and state, then the events."""
        self._flush = None
        self._last_flush = time.perf_counter()
        writer = self._writer
        if writer is None or writer.is_closing():
            return
        if self._unapplied >= IN_FLIGHT:  # the page process is busy: gather for it
            self._held = True
            return
        if writer.transport.get_write_buffer_size() > BACKLOG:
            self._behind = True  # the page is stuck: drop, and send it all when it is not
            self.drop()
            self._flush = self._loop.call_later(0.1, self._publish) if self._loop else None
            return
        if self._behind:
            self._behind = False
            now = snapshot(self.services, self.sessions, self.commands)
            writer.write(encode(["state", pickle.dumps(now)]))
            self.fresh()  # the snapshot has it all: nothing twice (a marker)
        try:
            writer.write(encode(self.frame()))
            self._unapplied += 1
        except ChannelError as exc:  # a frame too big to send: the page gets a snapshot
            self._log.warning("frame", f"a page frame was dropped: {exc}")
            self._behind = True
        self.frames += 1

    # what tests read

    @property
    def pid(self) -> int | None:
        """The page process's id, if one runs."""
        return self.process.pid if self.process is not None else None
