"""When the page is sent what changed: at most once per frame, the latest state wins.

The world tells the view of every change, possibly hundreds of thousands of
times a second; each call only records the new state and asks for a send. A
``SendScheduler`` runs the send on the asyncio loop at most once per period
(``1/hz``): a lone change after a quiet spell goes out at once, a flood goes
out once per period, and a request while one is due adds nothing.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable

__all__ = ["SendScheduler"]


class SendScheduler:
    """Calls ``send`` on the loop at most once per ``period_s``; see the module docstring.

    Attributes:
        period_s: Shortest time between two sends [s].
        sends: How many sends have run.
    """

    def __init__(self, period_s: float, send: Callable[[], None]) -> None:
        self.period_s = period_s
        self.sends = 0
        self._send = send
        self._loop: asyncio.AbstractEventLoop | None = None
        self._timer: asyncio.Handle | None = None
        self._last_s = -math.inf
        self._stopped = False

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Send on ``loop`` from now on (requests before this wait for it)."""
        self._loop = loop
        self.request()

    def request(self) -> None:
        """Send now if the last send is a period old, else once it is; never twice."""
        loop = self._loop
        if self._timer is not None or loop is None or self._stopped:
            return
        due = self._last_s + self.period_s
        if loop.time() >= due:
            self._timer = loop.call_soon(self._run)
        else:
            self._timer = loop.call_at(due, self._run)

    def stop(self) -> None:
        """No more sends; later calls do nothing."""
        self._stopped = True
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _run(self) -> None:
        self._timer = None
        if self._stopped or self._loop is None:
            return
        self._last_s = self._loop.time()
        self._send()
        self.sends += 1
