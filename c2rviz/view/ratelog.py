"""Warnings that a stranger can trigger, at most one line per kind per interval.

A page, or anything else that can reach the viewer's port, can send bad frames
as fast as it likes; each one must not cost a log line (let alone a traceback).
``RateLimitedLog`` lets the first warning of a kind through, holds back the
rest for ``interval_s`` and says, on the next line of that kind, how many it
held back.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from collections.abc import Callable

__all__ = ["RateLimitedLog"]


class RateLimitedLog:
    """At most one warning per key per ``interval_s``; held-back ones are counted.

    Attributes:
        interval_s: Shortest time between two lines of one key [s].
        max_keys: Keys remembered at most; keys are often made from what a
            stranger sent (an origin), so the table must not grow without bound.
    """

    def __init__(
        self,
        logger: logging.Logger,
        interval_s: float = 60.0,
        clock: Callable[[], float] = time.monotonic,
        max_keys: int = 1024,
    ) -> None:
        self.logger = logger
        self.interval_s = interval_s
        self.max_keys = max_keys
        self._clock = clock
        self._last_s: dict[str, float] = {}
        self._held: Counter[str] = Counter()

    def warning(self, key: str, message: str) -> bool:
        """Log ``message`` unless a line of ``key`` went out within the interval.

        Returns:
            Whether the line was logged.
        """
        now = self._clock()
        last = self._last_s.get(key)
        if last is not None and now - last < self.interval_s:
            self._held[key] += 1
            return False
        if last is None and len(self._last_s) >= self.max_keys:
            self._forget(now)
        held = self._held.pop(key, 0)
        self._last_s[key] = now
        if held:
            message += f" ({held} more like it held back in the last {self.interval_s:g} s)"
        self.logger.warning("%s", message)
        return True

    def _forget(self, now: float) -> None:
        """Drop keys whose interval is over; if none is, drop them all."""
        stale = [k for k, t in self._last_s.items() if now - t >= self.interval_s]
        for key in stale or list(self._last_s):
            del self._last_s[key]
            self._held.pop(key, None)
