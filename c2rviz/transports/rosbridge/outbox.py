"""One connection's subscription to one topic: a bounded outbox and the task that empties it.

rosbridge keeps one subscription per topic (as the client spelled it) per
client, however many subscribe requests (ids) it holds: roslibpy calls every
listener of a topic for each ``publish`` frame, so two frames per message
would reach each listener twice. Of its requests the subscription takes the
lowest ``throttle_rate`` and the highest ``queue_length``, as rosbridge does.

As in rosbridge_suite, ``queue_length`` buffers what a throttle holds back, and
only then: a subscription without a throttle (roslibpy's default, with its
default ``queue_length`` 0) is sent every message, and its outbox holds up to
``unthrottled_length`` messages (the server's largest ``queue_length``) for a
subscriber that reads more slowly than they come. The outbox holds at most that
many messages (at least one); a message that arrives when it is full pushes out
the oldest (latest wins, counted as ``thinned``). A subscriber that reads slowly,
or a throttle, thus thins the stream and never grows memory: the websocket's
write buffer (``write_limit``) plus this outbox is all a subscriber can hold.

Latest wins only where each message is whole (a joint state). A topic whose
messages are changes (markers added, deleted) gives a ``snapshot``: once a
message was pushed out, the next frame sent is the snapshot, the whole state
then, instead of what waits; the subscriber misses nothing but time.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import threading
import time
from collections import Counter, deque
from collections.abc import Awaitable, Callable
from typing import Any

from websockets.exceptions import ConnectionClosed

from .ops import FrameId

log = logging.getLogger("c2rviz.rosbridge")

Encode = Callable[[str, dict[str, Any]], "str | None"]


class Outbox:
    """The messages of one topic waiting to go to one client.

    Args:
        spelling: The topic as the client spelled it (its ``publish`` frames carry it).
        send: Sends one text frame to the client.
        encode: Makes the frame for ``(spelling, msg)``; None if it cannot be sent.
        stats: Counts ``thinned`` (messages pushed out unsent) and ``sent``.
        sent_probe: Called with the monotonic time [s] a message was delivered,
            just after its frame was written; for benchmarks, None otherwise.
        snapshot: Gives the topic's whole state (None: its messages are whole),
            sent instead of what waits after a message was pushed out.
        unthrottled_length: The messages held for a subscription without a
            throttle, whatever ``queue_length`` it asked (rosbridge ignores it then).
    """

    def __init__(
        self,
        spelling: str,
        send: Callable[[str], Awaitable[None]],
        encode: Encode,
        stats: Counter[str],
        sent_probe: Callable[[float], None] | None = None,
        snapshot: Callable[[], dict[str, Any] | None] | None = None,
        unthrottled_length: int = 100,
    ) -> None:
        self.spelling = spelling
        self.unthrottled_length = unthrottled_length
        self._snapshot = snapshot
        self._behind = False  # a message was pushed out: send the snapshot next
        self.handle: object = None
        self.requests: dict[FrameId, tuple[int, int]] = {}
        self._send, self._encode, self._stats, self._probe = send, encode, stats, sent_probe
        self._queue: deque[tuple[dict[str, Any], float]] = deque(maxlen=1)
        self._throttle_s = 0.0
        self._wake = asyncio.Event()
        self._loop = asyncio.get_running_loop()
        self._thread = threading.get_ident()
        self._closed = False
        self._task: asyncio.Task[None] | None = None

    @property
    def throttle_s(self) -> float:
        """The least time between two frames [s]: the lowest of the requests'."""
        return self._throttle_s

    @property
    def queue_length(self) -> int:
        """How many messages the outbox holds at most."""
        return self._queue.maxlen or 1

    def request(self, id: FrameId, throttle_rate_ms: int, queue_length: int) -> None:
        """Add (or change) subscribe request ``id``: throttle [ms] and queue length."""
        self.requests[id] = (throttle_rate_ms, queue_length)
        self._settle()

    def drop(self, id: FrameId) -> None:
        """Remove subscribe request ``id`` (all of them for None)."""
        if id is None:
            self.requests.clear()
        else:
            self.requests.pop(id, None)
        if self.requests:
            self._settle()

    def _settle(self) -> None:
        self._throttle_s = min(t for t, _ in self.requests.values()) / 1000.0
        if self._throttle_s > 0:
            length = max(1, max(q for _, q in self.requests.values()))
        else:  # queue_length buffers what a throttle holds back; without one, send all
            length = max(1, self.unthrottled_length)
        if length != self._queue.maxlen:
            self._queue = deque(self._queue, maxlen=length)

    def deliver(self, msg: dict[str, Any]) -> None:
        """Take one message (the ``Bridge``'s callback); from any thread, never blocks."""
        now = time.monotonic()
        if threading.get_ident() == self._thread:
            self._put(msg, now)
            return
        with contextlib.suppress(RuntimeError):  # a closed loop: the server is gone
            self._loop.call_soon_threadsafe(self._put, msg, now)

    def _put(self, msg: dict[str, Any], delivered: float) -> None:
        if self._closed:
            return
        if len(self._queue) == self._queue.maxlen:
            self._stats["thinned"] += 1
            self._behind = self._snapshot is not None
        self._queue.append((msg, delivered))
        self._wake.set()

    def start(self) -> None:
        """Start the task that sends the outbox's messages."""
        self._task = asyncio.create_task(self._pump(), name=f"rosbridge outbox {self.spelling}")

    async def close(self) -> None:
        """Stop sending; the messages still waiting are dropped."""
        self._closed = True
        self._queue.clear()
        if self._task is not None:
            self._task.cancel()
            await asyncio.gather(self._task, return_exceptions=True)

    def _catch_up(self) -> None:
        """Put the topic's whole state in place of what waits (if its messages are changes)."""
        self._behind = False
        assert self._snapshot is not None
        whole = self._snapshot()
        if whole is not None:
            self._queue.clear()
            self._queue.append((whole, time.monotonic()))

    async def _pump(self) -> None:
        loop = asyncio.get_running_loop()
        last_sent = -float("inf")
        try:
            while True:
                await self._wake.wait()
                self._wake.clear()
                while self._queue:
                    wait_s = last_sent + self._throttle_s - loop.time()
                    if wait_s > 0:
                        await asyncio.sleep(wait_s)  # newer messages push older ones out meanwhile
                        continue
                    if self._behind:
                        self._catch_up()
                    msg, delivered = self._queue.popleft()
                    text = self._encode(self.spelling, msg)
                    if text is None:
                        continue
                    await self._send(text)
                    last_sent = loop.time()
                    self._stats["sent"] += 1
                    if self._probe is not None:
                        self._probe(delivered)
        except ConnectionClosed:
            pass  # the connection's handler sees it too, and closes this outbox
        except Exception:
            log.exception("rosbridge: the outbox of %s stopped", self.spelling)
