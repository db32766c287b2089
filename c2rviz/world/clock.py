"""The one clock: every part that needs the time or a timer asks it.

Motion frames, ``sleep``, ``watch`` stamps, recordings, collision checks and the
page's time all come from the world's ``Clock``, which the program makes once
(``--clock``, ``clocks.parse_clock``) and hands to the world. So a faster or simulated
clock is one object to swap, and every part agrees on what time it is.

A clock gives the time ``now()`` [s] (any origin; never goes back) and timers on
the running asyncio loop: ``call_at(when, fn, *args)`` runs ``fn`` once the clock
reads ``when``, and ``call_later(delay, fn, *args)`` after ``delay`` of the
clock's seconds. Both return a handle with ``cancel()``.

- ``Clock``: real time, the monotonic clock asyncio's loop runs on (``--clock real``).
- ``ScaledClock(factor)``: time runs ``factor`` times faster than real time (its
  timers fire ``factor`` times sooner), from the moment it is made (``scaled:N``).
- ``clocks.VirtualClock``: time jumps to the next timer whenever nobody is busy
  (``virtual``): a program runs as fast as the CPU allows, with the same replies, the
  same order and the same stamps as in real time.

**Holds: how doors and sessions tell the clock they are busy or waiting.** A virtual
clock must not jump while a client is thinking about its next command, or while a
command is being worked on (an IK solve on the worker, a file being written): the
client would then act later, on the clock, than it would in real time. So:

- A door takes ``hold = clock.hold()`` for each client when it connects (the client
  is busy: time stands still), and ``hold.close()`` when it leaves.
- The door runs the client's commands inside ``with hold.acting():`` (for the
  coroutine of a reply that waits, create its task inside the block too). A reply
  that waits on the clock (``sleep``'s end, an arrival, rest after ``stop``/``wait``:
  ``Session.after``, ``world.moves.Travels`` and ``world.grips.Grips`` make these with
  ``clock.future()``) then releases the hold until it is settled; settling it takes
  the hold back at once, so the client is busy again before anything else can happen.
- A door whose client only listens (a ``watch`` stream, a subscription) and sends
  nothing may ``hold.release()`` until it sends again (``hold.take()``).
- ``with clock.busy():`` holds time for one piece of work that is not a client's.

Time jumps only when every hold is released; timers already due run at once whatever
the holds. With ``Clock`` and ``ScaledClock`` holds cost nothing: ``hold()`` is
``NO_HOLD``, whose methods do nothing.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import Any, Protocol

__all__ = [
    "ACTING",
    "NO_HOLD",
    "Clock",
    "Hold",
    "ScaledClock",
    "Timer",
]


class Timer(Protocol):
    """A pending call: ``cancel()`` stops it if it has not run."""

    def cancel(self) -> None: ...


class Hold:
    """One client's (or one piece of work's) claim that time must not jump now.

    The base class is ``NO_HOLD``'s: it does nothing (real and scaled time wait for
    nobody). ``VirtualClock`` hands out holds that count.
    """

    def take(self) -> None:
        """The holder is busy again (it sent a command): time stands still."""

    def release(self) -> None:
        """The holder only listens now: time may jump as far as the holder goes."""

    def close(self) -> None:
        """The holder is gone: it holds nothing from now on (``take`` does nothing)."""

    def wait_began(self) -> None:
        """A reply of this holder began waiting on the clock (``Clock.future``)."""

    def wait_ended(self) -> None:
        """That reply is settled: the holder is busy again."""

    @contextlib.contextmanager
    def acting(self) -> Iterator[None]:
        """Inside: the replies that wait on the clock (created here, or by a task created
        here) release this hold while they wait."""
        token = ACTING.set(self)
        try:
            yield
        finally:
            ACTING.reset(token)


NO_HOLD = Hold()
"""The hold of a clock that waits for nobody."""

ACTING: ContextVar[Hold | None] = ContextVar("c2rviz_acting_hold", default=None)
"""The hold of the client whose command runs now (``Hold.acting``)."""


class Clock:
    """Real time: ``time.monotonic``, the clock of asyncio's default loop."""

    factor = 1.0
    """Clock seconds per real second (virtual time: unbounded, and 0 here means none)."""
    virtual = False
    """Time jumps ahead when nobody is busy (``hold`` counts)."""

    def now(self) -> float:
        """The time [s]."""
        return time.monotonic()

    def call_at(self, when: float, fn: Callable[..., Any], *args: Any) -> Timer:
        """Run ``fn(*args)`` on the running loop once the clock reads ``when`` [s]."""
        return asyncio.get_running_loop().call_at(when, fn, *args)

    def call_later(self, delay: float, fn: Callable[..., Any], *args: Any) -> Timer:
        """Run ``fn(*args)`` on the running loop ``delay`` [s of this clock] from now."""
        return self.call_at(self.now() + delay, fn, *args)

    def describe(self) -> str:
        """How ``--clock`` names this clock."""
        return "real"

    # Holds (see the module docstring); real time waits for nobody.

    def hold(self) -> Hold:
        """A new hold, taken: a client connected (``close`` it when it leaves)."""
        return NO_HOLD

    @contextlib.contextmanager
    def busy(self) -> Iterator[None]:
        """Time stands still inside (work that is no client's)."""
        hold = self.hold()
        try:
            yield
        finally:
            hold.close()

    def future(self) -> asyncio.Future[Any]:
        """A reply that waits on this clock (a sleep's end, an arrival, rest), on the running
        loop. With a virtual clock it releases the acting hold (``ACTING``) until it is
        settled, and settling it takes the hold back at once."""
        return asyncio.get_running_loop().create_future()


class ScaledClock(Clock):
    """Time that runs ``factor`` times faster (or slower) than real time."""

    def __init__(self, factor: float) -> None:
        """Start now, at the real monotonic time.

        Raises:
            ValueError: ``factor`` is not a finite number above 0.
        """
        if not (math.isfinite(factor) and factor > 0):
            raise ValueError(f"a clock's factor must be a finite number above 0, got {factor}")
        self.factor = float(factor)
        self._origin = time.monotonic()

    def now(self) -> float:
        return self._origin + (time.monotonic() - self._origin) * self.factor

    def call_at(self, when: float, fn: Callable[..., Any], *args: Any) -> Timer:
        real = self._origin + (when - self._origin) / self.factor
        return asyncio.get_running_loop().call_at(real, fn, *args)

    def describe(self) -> str:
        return f"scaled:{self.factor:g}"
