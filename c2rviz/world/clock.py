"""The one clock: every part that needs the time or a timer asks it.

Motion frames, ``sleep``, ``watch`` stamps, recordings, collision checks and the
page's time all come from the world's ``Clock``, which the program makes once
(``--clock``) and hands to the world. So a faster or simulated clock is one object
to swap, and every part agrees on what time it is.

A clock gives the time ``now()`` [s] (any origin; never goes back) and timers on
the running asyncio loop: ``call_at(when, fn, *args)`` runs ``fn`` once the clock
reads ``when``, and ``call_later(delay, fn, *args)`` after ``delay`` of the
clock's seconds. Both return a handle with ``cancel()``.

- ``Clock``: real time, the monotonic clock asyncio's loop runs on.
- ``ScaledClock(factor)``: time runs ``factor`` times faster than real time (its
  timers fire ``factor`` times sooner), from the moment it is made.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable
from typing import Any, Protocol

__all__ = ["Clock", "ScaledClock", "Timer"]


class Timer(Protocol):
    """A pending call: ``cancel()`` stops it if it has not run."""

    def cancel(self) -> None: ...


class Clock:
    """Real time: ``time.monotonic``, the clock of asyncio's default loop."""

    factor = 1.0
    """Clock seconds per real second."""

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
