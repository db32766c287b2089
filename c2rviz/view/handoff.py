"""Values from viser's thread to the asyncio loop: the newest per control, one run per turn.

viser calls our callbacks on its own thread; the world lives on the asyncio loop.
``Handoff.put(key, value)`` (viser's thread) keeps only the newest value of each
key and, if none was waiting, asks the loop to run it: however fast a page sends,
a control costs the loop at most one run per loop turn (the latest value wins).
``run(key, value)`` is then called on the loop with the value waiting at that
moment. Everything shared between the two threads is behind ``lock``.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

__all__ = ["Handoff"]

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class Handoff(Generic[K, V]):
    """The newest value of each key, handed from viser's thread to the loop."""

    def __init__(self, run: Callable[[K, V], None]) -> None:
        """Set up; ``run(key, value)`` is called on the loop for each value handed over."""
        self.lock = threading.Lock()
        self._run = run
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pending: dict[K, V] = {}

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Hand values to ``loop`` from now on (earlier ones were dropped)."""
        self._loop = loop

    def stop(self) -> None:
        """Drop values from now on."""
        self._loop = None

    @property
    def running(self) -> bool:
        """Values are handed over (between ``start`` and ``stop``)."""
        return self._loop is not None

    def put(self, key: K, value: V) -> None:
        """(viser's thread) ``value`` is the newest of ``key``; wake the loop if it must."""
        loop = self._loop
        if loop is None:
            return
        with self.lock:
            first = key not in self._pending
            self._pending[key] = value
        if first:
            with contextlib.suppress(RuntimeError):  # the loop is closed: we stop
                loop.call_soon_threadsafe(self._due, key)

    def waiting(self, key: K) -> bool:
        """A value of ``key`` waits to be run."""
        return key in self._pending

    def take(self, key: K) -> V | None:
        """(the loop) The value of ``key`` waiting now, taken; None if none waits."""
        with self.lock:
            return self._pending.pop(key, None)

    def defer(self, key: K, value: V) -> None:
        """(the loop) Keep ``value`` waiting, untouched, for a later ``take`` (unless a newer
        value of ``key`` came meanwhile, which wins)."""
        with self.lock:
            self._pending.setdefault(key, value)

    def _due(self, key: K) -> None:
        if self._loop is None:
            return
        value = self.take(key)
        if value is not None:
            self._run(key, value)
