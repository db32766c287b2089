"""When the page is sent what changed: at most once per frame, the latest state wins.

The world tells the view of every change, possibly hundreds of thousands of
times a second; each call only records the new state and asks for a send. A
``SendScheduler`` runs the send on the asyncio loop at most once per period
(``1/hz``): a lone change after a quiet spell goes out at once, a flood goes
out once per period, and a request while one is due adds nothing.

A send may come in slices: ``send`` returns True while work is left (many
robots to draw), and its next slice runs at the loop's next turn, after
whatever else waits (a client's line), so no slice holds the loop long. The
pace adapts to the cost: the next send starts no sooner than the last one's
time at work after it ended (``REST_PER_WORK``), so however many robots there
are, sends take at most about half of the loop and every robot still gets every
frame there is.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable

__all__ = ["REST_PER_WORK", "SendScheduler"]

REST_PER_WORK = 1.0
"""The loop's time left to other work after a send, per second the send worked."""


class SendScheduler:
    """Calls ``send`` on the loop at most once per ``period_s``; see the module docstring.

    Attributes:
        period_s: Shortest time between two sends' starts [s].
        sends: How many sends have run to their end.
        rest_per_work: The loop's time left to other work after a send, per second the
            send worked (``REST_PER_WORK``; the page process, which serves no client,
            leaves less).
        work_s: The last send's time at work, its slices summed [s of this thread's CPU
            time: a wait for the GIL while viser's thread encodes is not work].
    """

    def __init__(self, period_s: float, send: Callable[[], bool]) -> None:
        """``send`` draws (a slice of) what changed; it returns True if work is left."""
        self.period_s = period_s
        self.sends = 0
        self.work_s = 0.0
        self.rest_per_work = REST_PER_WORK
        self._send = send
        self._loop: asyncio.AbstractEventLoop | None = None
        self._timer: asyncio.Handle | None = None
        self._last_s = -math.inf  # the last send's start [s of the loop's clock]
        self._rest_until = -math.inf  # no send before this [s of the loop's clock]
        self._slicing = False  # a send is under way: its next slice is queued
        self._again = False  # asked for while slicing
        self._work = 0.0
        self._stopped = False

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Send on ``loop`` from now on (requests before this wait for it)."""
        self._loop = loop
        self.request()

    def request(self) -> None:
        """Send now if the last send is a period old, else once it is; never twice."""
        loop = self._loop
        if self._slicing:
            self._again = True  # after this send, for what changed while it ran
            return
        if self._timer is not None or loop is None or self._stopped:
            return
        due = max(self._last_s + self.period_s, self._rest_until)
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
        loop = self._loop
        if self._stopped or loop is None:
            return
        if not self._slicing:
            self._last_s = loop.time()
            self._work = 0.0
        began = time.thread_time()
        more = False
        try:
            more = self._send()
        finally:
            self._work += time.thread_time() - began
            if more and not self._stopped:
                self._slicing = True
                self._timer = loop.call_soon(self._run)
            else:
                self._end(loop)

    def _end(self, loop: asyncio.AbstractEventLoop) -> None:
        """A send is over: rest as long as it worked, then send again if asked meanwhile."""
        self._slicing = False
        self.work_s = self._work
        self._rest_until = loop.time() + self.rest_per_work * self._work
        self.sends += 1
        if self._again:
            self._again = False
            self.request()
