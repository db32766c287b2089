"""Latency on the world's clock: replies that come late, each in its turn.

A ``fault latency MS[,JITTER]`` makes every reply to a robot's clients come late
(docs/faults.md). ``fault_rules.FaultRules`` draws each reply's delay; this module makes
the reply wait it out on the world's clock, so virtual time runs it exactly:

- ``late``: one reply of a door that waits for each reply before it reads the next
  command (the text port, rosbridge's command lines): its text, an awaitable of it (a
  move's arrival) or the error it is refused with, handed back as an awaitable that
  gives the text, or raises the error, that much later.
- ``LateSends``: the messages of a door that sends without being asked (a CRCL
  connection's statuses), each sent that much later, never before the one made before
  it (a jitter draw cannot reorder them).
"""

from __future__ import annotations

import asyncio
from collections import deque
from collections.abc import Awaitable, Callable
from typing import Generic, TypeVar

from ..errors import C2rvizError
from .clock import Clock, Timer

__all__ = ["LateSends", "late"]

T = TypeVar("T")


def late(reply: str | Awaitable[str] | C2rvizError, delay_s: float, clock: Clock) -> Awaitable[str]:
    """``reply`` ``delay_s`` [s] later on ``clock``: an awaitable that gives its text (or
    raises the error it is, or ends with), ``delay_s`` after it is known.

    The waiting is on ``clock.future()``: with a virtual clock the acting client's hold is
    released meanwhile (``Clock.future``), as for any reply that waits on the clock.
    """
    if isinstance(reply, (str, C2rvizError)):
        future: asyncio.Future[str] = clock.future()
        clock.call_later(delay_s, _settle, future, reply)
        return future
    return _after(reply, delay_s, clock)


async def _after(reply: Awaitable[str], delay_s: float, clock: Clock) -> str:
    """``reply`` once it comes (its text, or the error it ends with), ``delay_s`` later."""
    outcome: str | C2rvizError
    try:
        outcome = await reply
    except C2rvizError as error:
        outcome = error
    return await late(outcome, delay_s, clock)


def _settle(future: asyncio.Future[str], outcome: str | C2rvizError) -> None:
    if future.done():
        return
    if isinstance(outcome, C2rvizError):
        future.set_exception(outcome)
    else:
        future.set_result(outcome)


class LateSends(Generic[T]):
    """One client's messages, each sent ``delay()`` [s] late on ``clock``, in order.

    Args:
        send: Sends one message now.
        delay: The delay [s] of the message made now (0: none; a draw per message).
        clock: The world's clock.
    """

    def __init__(self, send: Callable[[T], None], delay: Callable[[], float], clock: Clock) -> None:
        self._send = send
        self._delay = delay
        self._clock = clock
        self._waiting: deque[tuple[float, T]] = deque()
        self._timer: Timer | None = None

    @property
    def waiting(self) -> int:
        """Messages made but not yet sent."""
        return len(self._waiting)

    def send(self, message: T) -> None:
        """Send ``message`` now, or once its delay is over and those before it are sent."""
        delay = self._delay()
        if delay <= 0.0 and not self._waiting:
            self._send(message)
            return
        due = self._clock.now() + max(delay, 0.0)
        if self._waiting:
            due = max(due, self._waiting[-1][0])  # never before the one made before it
        self._waiting.append((due, message))
        if self._timer is None:
            self._timer = self._clock.call_at(self._waiting[0][0], self._due)

    def close(self) -> None:
        """The client is gone: what still waits is never sent."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self._waiting.clear()

    def _due(self) -> None:
        self._timer = None
        now = self._clock.now()
        while self._waiting and self._waiting[0][0] <= now:
            self._send(self._waiting.popleft()[1])
        if self._waiting:
            self._timer = self._clock.call_at(self._waiting[0][0], self._due)
