"""The cameras' lines in ``watch`` streams: ``camera NAME T p1:TYPE:x,y,z,roll,pitch,yaw;...``.

While anyone watches, each camera whose rate is above 0 reports what it sees every
``1 / rate`` seconds of the world's clock (the first at once), to every active stream,
in each connection's units (``ok none``'s ``none`` when it sees nothing). T counts from
the server's start, as ``state`` lines do. The lines go with the stream's events: a
reader too slow to take them loses the oldest (``event dropped N``).

On virtual time a camera's next line is never the only thing that moves the clock: when
nobody holds it and no other timer is pending, the camera waits (parked) until the next
command anyone sends, so a server whose clients only watch does not spin.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol

from ..world.camera_sight import seen_text, sight
from ..world.clock import Timer

if TYPE_CHECKING:
    from ..world.world import World

__all__ = ["CameraFeed"]


class _Units(Protocol):
    @property
    def angle_scale(self) -> float: ...


class _Stream(Protocol):
    @property
    def session(self) -> _Units: ...

    def event(self, text: str, seq: int) -> None: ...


class _Hub(Protocol):
    """What the feed needs of its ``watch.WatchHub``."""

    world: World
    origin: float

    @property
    def active(self) -> Sequence[_Stream]: ...

    def next_seq(self) -> int: ...


class CameraFeed:
    """The periodic camera lines of one ``WatchHub``."""

    def __init__(self, hub: _Hub) -> None:
        self.hub = hub
        self._timers: dict[str, Timer] = {}
        self._due: dict[str, float] = {}  # when each camera's next line is due [clock s]
        self._period: dict[str, float] = {}
        self._parked: set[str] = set()

    def sync(self) -> None:
        """Start, re-rate or stop the cameras' lines as the cameras and streams are now."""
        world = self.hub.world
        wanted = {}
        if self.hub.active:
            wanted = {c.name: 1.0 / c.rate_hz for c in world.cameras.all() if c.rate_hz > 0}
        for name in list(self._period):
            if wanted.get(name) != self._period[name]:
                self._stop(name)
        now = world.clock.now()
        for name, period in wanted.items():
            if name not in self._period:
                self._period[name] = period
                self._arm(name, now)

    def wake(self) -> None:
        """Someone sent a command: parked cameras go on."""
        if self._parked:
            now = self.hub.world.clock.now()
            for name in sorted(self._parked):
                self._arm(name, max(self._due[name], now))
            self._parked.clear()

    def _stop(self, name: str) -> None:
        timer = self._timers.pop(name, None)
        if timer is not None:
            timer.cancel()
        self._parked.discard(name)
        self._due.pop(name, None)
        self._period.pop(name, None)

    def _arm(self, name: str, when: float) -> None:
        self._due[name] = when
        self._timers[name] = self.hub.world.clock.call_at(when, self._tick, name)

    def _tick(self, name: str) -> None:
        self._timers.pop(name, None)
        hub = self.hub
        world = hub.world
        if name not in self._period or name not in world.cameras:
            self._stop(name)
            return
        clock = world.clock
        now = clock.now()
        seen = sight(world, name)
        seq = hub.next_seq()
        stamp = f"{max(now, self._due[name]) - hub.origin:.6f}"
        for stream in hub.active:
            text = seen_text(seen, stream.session.angle_scale)
            stream.event(f"camera {name} {stamp} {text}", seq)
        due = self._due[name] + self._period[name]
        if due <= now:  # late (a busy loop on real time): no burst of catch-up lines
            due = now + self._period[name]
        next_timer = getattr(clock, "next_timer", None)
        idle = getattr(clock, "busy_count", 1) == 0
        if next_timer is not None and idle and next_timer(self._tick) is None:
            self._due[name] = due
            self._parked.add(name)
            return
        self._arm(name, due)
