"""The ``watch`` stream: the arm's state and what happens, as lines on a client's socket.

A connection that sent ``watch [HZ]`` also receives, between its replies::

    state T v0,...,vn-1      the arm at T [s since the server started], in its units
    event marker x,y,z,roll,pitch,yaw SHAPE r,g,b   a marker (base frame, its units)
    event clear              every marker is gone
    event arrived            a move came to rest at its target
    event stopped            a move came to rest after ``stop``
    event collision a~b,...  the colliding pairs changed (``none``: clear again), once
                             collisions are checked (an object, ``collisions``, ``guard on``)
    event grasped NAME       a gripper took part NAME (docs/parts.md)
    event released NAME      a gripper let go of part NAME
    event resting NAME on X  part NAME came to rest on X (an object, a part, floor)
    event record-stopped NAME: WHY
    event fault KIND [ARGS]  a fault began (docs/faults.md; ARGS in SI, latency in ms)
    event cleared KIND [ARGS]   it ended (``fault clear``)
    event reset              ``reset`` lifted a stop
    event dropped N          N events were dropped for a reader too slow to take them
    camera NAME T SEEN       what camera NAME sees at T, at its rate (docs/cameras.md)

A slow reader costs neither memory nor other clients: a stream keeps only the
latest state (a reader that falls behind skips states) and at most
``MAX_EVENTS`` events (the oldest go first, counted in ``event dropped N``).
Lines are written only while the socket's write buffer is below
``STREAM_HIGH_BYTES`` (asyncio's write flow control: the connection forwards
``pause_writing``/``resume_writing``), so a watcher that never reads is never
disconnected for it: at most ``STREAM_ALLOWANCE_BYTES`` of its buffer are stream
lines, and the unread-replies limit does not count them.

``WatchHub`` is one per world (the app makes it, and hands it to the sessions
and the doors): the observer that fans the world's effects out to the active
streams, and the event texts to its listeners (``listen``: consumers without a
socket, such as rosbridge's ``/c2rviz/events``). It is in the world's
observers only while someone watches or listens, so an unwatched server pays
nothing. ``WatchStream`` is one per connection.
"""

from __future__ import annotations

import asyncio
import math
from collections import deque
from collections.abc import Callable, Sequence
from typing import Protocol

from ..errors import C2rvizError
from ..protocol import replies
from ..robot.frames import in_base, se3_pose, wxyz_se3
from ..world.cameras import Camera, Seen
from ..world.clock import Timer
from ..world.observer import Observer
from ..world.state import Marker, RobotState
from ..world.world import World, seen_text
from .camera_feed import CameraFeed

MAX_EVENTS = 256
"""Events a stream holds for a reader that does not take them; past it the oldest go."""
STREAM_HIGH_BYTES = 16 * 1024
"""A watching connection's write buffer above this pauses the stream (asyncio's high-water
mark); it goes on below a quarter of it."""
STREAM_ALLOWANCE_BYTES = STREAM_HIGH_BYTES + MAX_EVENTS * 1024
"""Most stream output that can sit in a connection's write buffer: one write past the
high-water mark (the dropped count, every held event, a state). The unread-replies limit
counts only what is beyond it."""


EventListener = Callable[[str | None, str], None]
"""``listener(robot, text)``: an event of ``robot`` (None: of every robot), its text as a
``watch`` line gives it after ``event `` (``arrived``, ``marker x,y,z,roll,pitch,yaw SHAPE
r,g,b`` with angles in radians); for consumers without a socket (rosbridge's events topic)."""


class NotAConnection(C2rvizError):
    """``watch`` from a source that is not a TCP connection (the page)."""

    def __init__(self, source: str) -> None:
        self.source = source
        super().__init__(
            f"watch: {source} has no stream of its own; watch from a TCP connection "
            "(for instance c2rviz-cli --watch)"
        )


class Sink(Protocol):
    """Where a stream writes: the connection (``server.Connection``)."""

    @property
    def transport(self) -> asyncio.Transport | None: ...

    @property
    def closing(self) -> bool: ...


class Watcher(Protocol):
    """What a stream needs of the session it serves (``session.Session``)."""

    source: str
    state: RobotState

    @property
    def angle_scale(self) -> float: ...

    def now(self) -> tuple[float, ...]: ...

    def from_si(self, values: Sequence[float]) -> list[float]: ...


class WatchStream:
    """One connection's stream: the latest state and the events not yet written.

    Each item gets a sequence number from the hub, so events and the state are written
    in the order they happened; states are coalesced (only the latest is kept) and
    written at most once per ``period_s``.
    """

    def __init__(self, hub: WatchHub, session: Watcher, sink: Sink) -> None:
        self.hub = hub
        self.session = session
        self.sink = sink
        self.active = False
        self.period_s = 0.0
        self.robot = ""
        self.paused = False
        self.used = False
        """This connection has watched: its write buffer may hold stream lines."""
        self._q: tuple[float, ...] | None = None  # the pending state [rad or m]
        self._t = 0.0  # its clock time [s]
        self._seq = 0  # its place among the events
        self._last_t = -math.inf  # clock time of the last state line [s]
        self._events: deque[tuple[int, str]] = deque()
        self._dropped = 0
        self._handle: Timer | None = None

    def start(self, hz: float) -> None:
        """Stream at most ``hz`` states a second [1/s], beginning with the state now."""
        self.period_s = 1.0 / hz
        self.robot = self.session.state.name
        if not self.used:
            self.used = True
            transport = self.sink.transport
            if transport is not None:
                transport.set_write_buffer_limits(high=STREAM_HIGH_BYTES)
        self.active = True
        self.state(self.session.now(), self.hub.world.clock.now(), self.hub.next_seq())

    def stop(self) -> None:
        """Write nothing more (what is held is dropped)."""
        self.active = False
        self._q = None
        self._events.clear()
        self._dropped = 0
        self._last_t = -math.inf
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None

    # What the hub hands over.

    def state(self, q: tuple[float, ...], t: float, seq: int) -> None:
        self._q = q
        self._t = t
        self._seq = seq
        if self._handle is None and not self.paused:
            self._handle = self.hub.world.clock.call_later(0.0, self._flush)

    def event(self, text: str, seq: int) -> None:
        events = self._events
        if len(events) >= MAX_EVENTS:
            events.popleft()
            self._dropped += 1
        events.append((seq, text))
        if self._handle is None and not self.paused:
            self._handle = self.hub.world.clock.call_later(0.0, self._flush)

    # Write flow control (forwarded by the connection).

    def pause(self) -> None:
        self.paused = True
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None

    def resume(self) -> None:
        self.paused = False
        if self.active and self._handle is None and (self._q is not None or self._events):
            self._handle = self.hub.world.clock.call_later(0.0, self._flush)

    def _flush(self) -> None:
        """Write the events, and the state when one is due; come back when the next is."""
        self._handle = None
        sink = self.sink
        transport = sink.transport
        if not self.active or self.paused or sink.closing or transport is None:
            return
        if transport.is_closing():
            return
        lines = []
        if self._dropped:
            lines.append(f"event dropped {self._dropped}")
            self._dropped = 0
        events = self._events
        q = self._q
        while events and (q is None or events[0][0] < self._seq):
            lines.append(events.popleft()[1])
        if q is not None:
            now = self.hub.world.clock.now()
            due = self._last_t + self.period_s
            if now >= due:
                t = max(self._t, due)  # the state is the latest: the arm showed it at t
                q = self.hub.world.faults.sensed(self.robot, q)  # encoder noise, if on
                values = replies.numbers(self.session.from_si(q))
                lines.append(f"state {t - self.hub.origin:.6f} {values}")
                self._last_t = t
                self._q = None
                while events:
                    lines.append(events.popleft()[1])
            else:
                self._handle = self.hub.world.clock.call_at(due, self._flush)
        if lines:
            lines.append("")
            transport.write("\n".join(lines).encode())


class WatchHub(Observer):
    """The streams of one world, and the observer that feeds them."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.origin = world.clock.now()
        """Clock time [s] that ``state`` lines count from (the server's start)."""
        self.streams: dict[Watcher, WatchStream] = {}
        self.active: list[WatchStream] = []
        self.listeners: list[EventListener] = []
        self._seq = 0
        self.cameras = CameraFeed(world, self._camera)
        """The cameras' ``camera NAME T ...`` lines (``camera_feed.py``)."""

    @property
    def default_hz(self) -> float:
        """The frame rate [1/s]: a watcher's default."""
        return 1.0 / self.world.frame_s

    def next_seq(self) -> int:
        self._seq += 1
        return self._seq

    # Connections.

    def open(self, session: Watcher, sink: Sink) -> WatchStream:
        """The (idle) stream of a new connection."""
        stream = self.streams[session] = WatchStream(self, session, sink)
        return stream

    def close(self, session: Watcher) -> None:
        """The connection is gone."""
        stream = self.streams.pop(session, None)
        if stream is not None:
            self._deactivate(stream)

    def watch(self, session: Watcher, hz: float | None) -> None:
        """Start (or re-rate) ``session``'s stream.

        Raises:
            NotAConnection: the session has no connection (the page).
        """
        stream = self.streams.get(session)
        if stream is None:
            raise NotAConnection(session.source)
        stream.start(self.default_hz if hz is None else hz)
        if stream not in self.active:
            self._engage()
            self.active.append(stream)
        self.cameras.sync(bool(self.active))

    def unwatch(self, session: Watcher) -> bool:
        """Stop ``session``'s stream; False if it was not watching."""
        stream = self.streams.get(session)
        if stream is None or not stream.active:
            return False
        self._deactivate(stream)
        return True

    def _deactivate(self, stream: WatchStream) -> None:
        stream.stop()
        if stream in self.active:
            self.active.remove(stream)
            self._disengage()
            self.cameras.sync(bool(self.active))

    # Listeners: event texts for consumers without a socket.

    def listen(self, listener: EventListener) -> None:
        """Call ``listener(robot, text)`` with every event from now on."""
        self._engage()
        self.listeners.append(listener)

    def unlisten(self, listener: EventListener) -> None:
        """Stop calling ``listener``; idempotent."""
        if listener in self.listeners:
            self.listeners.remove(listener)
            self._disengage()

    def _engage(self) -> None:
        """Someone is about to need the world's effects: be among its observers."""
        if not self.active and not self.listeners:
            self.world.add_observers([self])

    def _disengage(self) -> None:
        """Nobody needs them any more: an unwatched server pays nothing."""
        if not self.active and not self.listeners:
            self.world.remove_observer(self)

    def event(self, text: str, robot: str | None = None) -> None:
        """Tell every watcher (of ``robot``, or all) ``event TEXT``, and every listener."""
        seq = self.next_seq()
        line = f"event {text}"
        for stream in self.active:
            if robot is None or stream.robot == robot:
                stream.event(line, seq)
        for listener in list(self.listeners):
            listener(robot, text)

    # The world's effects.

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        self._seq = seq = self._seq + 1  # on every command of a flood: kept lean
        values = q if q.__class__ is tuple else tuple(q)
        for stream in self.active:
            if stream.robot == robot:
                stream.state(values, t, seq)

    def on_marker(self, robot: str, marker: Marker) -> None:
        seq = self.next_seq()
        x, y, z, roll, pitch, yaw = se3_pose(
            in_base(self.world.robots[robot].base, wxyz_se3(marker.position, marker.wxyz))
        )
        rgb = replies.numbers(marker.rgb)
        for stream in self.active:
            if stream.robot == robot:
                angle = stream.session.angle_scale
                pose = replies.numbers([x, y, z, roll / angle, pitch / angle, yaw / angle])
                stream.event(f"event marker {pose} {marker.shape} {rgb}", seq)
        if self.listeners:
            text = f"marker {replies.numbers([x, y, z, roll, pitch, yaw])} {marker.shape} {rgb}"
            for listener in list(self.listeners):
                listener(robot, text)

    def on_clear_markers(self, robot: str) -> None:
        self.event("clear", robot)

    def on_arrived(self, robot: str) -> None:
        self.event("arrived", robot)

    def on_stopped(self, robot: str) -> None:
        self.event("stopped", robot)

    def on_collisions(self, robot: str, pairs: Sequence[tuple[str, str]]) -> None:
        self.event(f"collision {replies.pairs(pairs)}", robot)

    def on_fault(self, robot: str, text: str) -> None:
        self.event(text, robot)

    def on_part_event(self, robot: str | None, text: str) -> None:
        self.event(text)  # parts are the world's: every watcher hears of them

    # The cameras' lines (camera_feed.py).

    def _camera(self, name: str, t: float, seen: Sequence[Seen]) -> None:
        seq = self.next_seq()
        stamp = f"{t - self.origin:.6f}"
        for stream in self.active:
            text = seen_text(seen, stream.session.angle_scale)
            stream.event(f"camera {name} {stamp} {text}", seq)

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        self.cameras.sync(bool(self.active))

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.cameras.wake()

    def on_commands(self, source: str, lines: Sequence[str]) -> None:
        self.cameras.wake()  # once is enough: the first wakes the parked cameras
