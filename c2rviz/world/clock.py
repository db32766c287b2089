"""The one clock: every part that needs the time or a timer asks it; and replies made late on it.

Motion frames, ``sleep``, ``watch`` stamps, recordings, collision checks and the
page's time all come from the world's ``Clock``, which the program makes once
(``--clock``, ``virtual_clock.parse_clock``) and hands to the world. So a faster or simulated
clock is one object to swap, and every part agrees on what time it is.

A clock gives the time ``now()`` [s] (any origin; never goes back) and timers on
the running asyncio loop: ``call_at(when, fn, *args)`` runs ``fn`` once the clock
reads ``when``, and ``call_later(delay, fn, *args)`` after ``delay`` of the
clock's seconds. Both return a handle with ``cancel()``.

- ``Clock``: real time, the monotonic clock asyncio's loop runs on (``--clock real``).
- ``ScaledClock(factor)``: time runs ``factor`` times faster than real time (its
  timers fire ``factor`` times sooner), from the moment it is made (``scaled:N``).
- ``virtual_clock.VirtualClock``: time jumps to the next timer whenever nobody is busy
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

**Latency on the clock** (the end of this module): replies that come late, each in its turn.

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
import contextlib
import math
import time
from collections import deque
from collections.abc import Awaitable, Callable, Iterator
from contextvars import ContextVar
from typing import Any, Generic, Protocol, TypeVar

from ..errors import C2rvizError


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
