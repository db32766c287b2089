"""Which clock (``parse_clock`` reads ``--clock``: ``real``, ``scaled:N``, ``virtual``),
and virtual time (``--clock virtual``): the clock jumps to its next timer whenever nobody
is busy, so a program runs as fast as the CPU allows.

Every client of every door holds the clock while it is busy — connected and not
waiting for a reply that waits on the clock (see ``clock``'s docstring: holds, and
how doors use them). When every hold is released (each client waits for a ``sleep``
to end, an arrival, the arm at rest, or only listens), the clock reads the time of
its earliest timer and runs every timer due then, in the order real time would
have (by time, then by when they were set). Settling a reply that waited takes its
client's hold back at once, before any other callback runs, so the client's next
command happens at the same clock time as it would in real time: the same replies,
the same order, the same recorded stamps (real time's only differ by the loop's
lateness, well within a frame).

Timers already due run at once, holds or not; nothing else of asyncio changes (I/O,
``call_soon``, real-time timers of the doors keep the loop's own clock).
"""

from __future__ import annotations

import asyncio
import contextlib
import heapq
import math
from collections.abc import Callable
from typing import Any

from ..errors import ConfigError
from .clock import ACTING, Clock, Hold, ScaledClock, Timer


class VirtualHold(Hold):
    """A hold that counts: held unless released, waiting on the clock, or closed."""

    __slots__ = ("_clock", "_closed", "_held", "_released", "_waits")

    def __init__(self, clock: VirtualClock) -> None:
        self._clock = clock
        self._released = False
        self._waits = 0
        self._closed = False
        self._held = True
        clock.busy_count += 1

    @property
    def held(self) -> bool:
        """Time cannot jump because of this holder now."""
        return self._held

    def take(self) -> None:
        self._released = False
        self._update()

    def release(self) -> None:
        self._released = True
        self._update()

    def close(self) -> None:
        self._closed = True
        self._update()

    def wait_began(self) -> None:
        self._waits += 1
        self._update()

    def wait_ended(self) -> None:
        self._waits = max(0, self._waits - 1)
        self._update()

    def _update(self) -> None:
        held = not self._closed and not self._released and self._waits == 0
        if held == self._held:
            return
        self._held = held
        clock = self._clock
        if held:
            clock.busy_count += 1
        else:
            clock.busy_count -= 1
            if clock.busy_count == 0:
                clock.poke()


class TimedFuture(asyncio.Future[Any]):
    """A reply that waits on the virtual clock: its client's hold is released while it
    waits, and taken back the instant it is settled (before any callback runs)."""

    def __init__(self, hold: VirtualHold, *, loop: asyncio.AbstractEventLoop) -> None:
        super().__init__(loop=loop)
        self._hold: VirtualHold | None = hold
        hold.wait_began()

    def _woke(self) -> None:
        hold, self._hold = self._hold, None
        if hold is not None:
            hold.wait_ended()

    def set_result(self, result: Any) -> None:
        if not self.done():
            self._woke()
        super().set_result(result)

    def set_exception(self, exception: type | BaseException) -> None:
        if not self.done():
            self._woke()
        super().set_exception(exception)

    def cancel(self, msg: Any | None = None) -> bool:
        if not self.done():
            self._woke()
        return super().cancel(msg)


class _Timer:
    """A timer on the virtual clock (cancelled lazily: it stays in the heap, skipped)."""

    __slots__ = ("args", "cancelled", "fn", "handle")

    def __init__(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.fn = fn
        self.args = args
        self.cancelled = False
        self.handle: asyncio.Handle | None = None

    def cancel(self) -> None:
        self.cancelled = True
        if self.handle is not None:
            self.handle.cancel()


class VirtualClock(Clock):
    """Time that stands still while anyone is busy and jumps to the next timer when not.

    Attributes:
        busy_count: Holds held now (time jumps only at 0).
        jumps: How many times time has jumped (for tests and benchmarks).
    """

    factor = 0.0
    virtual = True

    def __init__(self, start: float = 0.0) -> None:
        """Start at ``start`` [s]."""
        self._now = float(start)
        self._heap: list[tuple[float, int, _Timer]] = []
        self._seq = 0
        self._loop: asyncio.AbstractEventLoop | None = None
        self._poked = False
        self.busy_count = 0
        self.jumps = 0

    def now(self) -> float:
        return self._now

    def describe(self) -> str:
        return "virtual"

    def call_at(self, when: float, fn: Callable[..., Any], *args: Any) -> Timer:
        loop = self._loop = asyncio.get_running_loop()
        if when <= self._now:  # due: at once, whoever holds
            return loop.call_soon(fn, *args)
        timer = _Timer(fn, args)
        self._seq += 1
        heapq.heappush(self._heap, (when, self._seq, timer))
        if self.busy_count == 0:
            self.poke()
        return timer

    def next_timer(self, ignore: Callable[..., Any] | None = None) -> float | None:
        """When the earliest timer not cancelled (and not of ``ignore``) is due [s], or None:
        for a periodic job that should not be the only thing moving time (the cameras'
        ``watch`` lines)."""
        live = [
            when
            for when, _, timer in self._heap
            if not timer.cancelled and (ignore is None or timer.fn != ignore)
        ]
        return min(live) if live else None

    # Holds.

    def hold(self) -> Hold:
        if self._loop is None:
            with contextlib.suppress(RuntimeError):
                self._loop = asyncio.get_running_loop()
        return VirtualHold(self)

    def future(self) -> asyncio.Future[Any]:
        loop = self._loop = asyncio.get_running_loop()
        hold = ACTING.get()
        if not isinstance(hold, VirtualHold):
            return loop.create_future()  # nobody's reply (a door without holds): nothing held
        return TimedFuture(hold, loop=loop)

    # Jumping.

    def poke(self) -> None:
        """Nobody may be busy: look (once, soon) whether time can jump."""
        if not self._poked and self._loop is not None and not self._loop.is_closed():
            self._poked = True
            self._loop.call_soon(self._advance)

    def _advance(self) -> None:
        """Nobody holds: go to the earliest timer and run every timer due then."""
        self._poked = False
        if self.busy_count > 0 or self._loop is None:
            return
        heap = self._heap
        while heap and heap[0][2].cancelled:
            heapq.heappop(heap)
        if not heap:
            return
        when = heap[0][0]
        if when > self._now:
            self._now = when
            self.jumps += 1
        loop = self._loop
        while heap and heap[0][0] <= self._now:
            timer = heapq.heappop(heap)[2]
            if not timer.cancelled:
                timer.handle = loop.call_soon(timer.fn, *timer.args)
        if self.jumps % 1024 == 0 and len(heap) > 64:  # drop what was cancelled long ago
            self._heap = heap = [entry for entry in heap if not entry[2].cancelled]
            heapq.heapify(heap)
        if heap:
            self.poke()  # after the callbacks just queued: they may take holds back


CLOCK_FORMS = ("real", "scaled:N", "virtual")
"""What ``--clock`` accepts (N: a finite number above 0, the clock seconds per real second)."""


def parse_clock(text: str, name: str = "--clock") -> Clock:
    """The clock ``--clock TEXT`` names: ``real``, ``scaled:N`` or ``virtual``.

    Args:
        text: The clock's form.
        name: Where it was given, for the message (``--clock``, ``[options] clock``).

    Raises:
        ConfigError: any other text, a factor that is not a finite number above 0
            (``scaled:0``, negative, ``nan``, ``inf``), naming the valid forms.
    """
    word = text.strip().lower()
    if word == "real":
        return Clock()
    if word == "virtual":
        return VirtualClock()
    kind, colon, number = word.partition(":")
    if kind == "scaled" and colon:
        try:
            factor = float(number)
        except ValueError:
            factor = math.nan
        if math.isfinite(factor) and factor > 0:
            return ScaledClock(factor)
        raise ConfigError(
            f"{name} {text}: the factor must be a finite number above 0 "
            "(scaled:10 runs ten times faster)",
            CLOCK_FORMS,
        )
    raise ConfigError(f"{name} {text!r} is not a clock", CLOCK_FORMS)
