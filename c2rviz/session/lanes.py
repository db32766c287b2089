"""A kind of heavy work with its own threads: ``Lane``, per-owner queues served in turn.

Each job belongs to an owner (a session: one connection; None for the server's own
work, such as the guard's re-checks). An owner's jobs wait in its own queue, in
order; the lane takes the next job from each owner with work in turn (round
robin), so a client with a long queue delays its own work, not the others'. An
``urgent`` job goes before every queue. A job with a ``key`` replaces the one with
the same key still waiting (latest wins; the older hears ``Superseded``); a
running job with that key is asked to stop (its ``Cancel``, if it has one: a plan).

The lane is bounded twice: ``max_queue`` jobs waiting in all, and ``max_per_owner``
waiting for one owner; one more is refused at once with ``WorkerBusy``. With
``one_per_owner`` an owner runs one job at a time, so several threads serve
several owners side by side, never one owner's burst.
"""

from __future__ import annotations

import asyncio
import functools
from collections import deque
from collections.abc import Callable, Hashable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

from ..errors import C2rvizError, MotionInterrupted
from ..planning.errors import SUPERSEDED, WENT_AWAY, Cancel, PlanCancelled


class WorkerBusy(C2rvizError):
    """A lane's queue is full (in all, or this connection's): refused, nothing changed."""

    def __init__(self, limit: int, mine: bool = False) -> None:
        self.limit = limit
        self.mine = mine
        if mine:
            text = (
                f"the server is busy: this connection has {limit} heavy commands (checks, IK, "
                "plans) waiting already, its limit; try again"
            )
        else:
            text = (
                f"the server is busy: {limit} heavy commands (checks, IK, plans) wait already, "
                "its limit; try again"
            )
        super().__init__(text)


class Superseded(MotionInterrupted):
    """A job replaced by a newer one with the same key before it ran."""

    def __init__(self) -> None:
        super().__init__("superseded by a newer command before it was checked")


@dataclass(eq=False)
class Job:
    """One piece of work: what runs, who awaits it, and what it is known by."""

    fn: Callable[[], Any]
    future: asyncio.Future[Any]
    owner: object = None
    key: Hashable | None = None
    cancel: Cancel | None = None


class Lane:
    """Threads for one kind of work and the owners' queues in front of them (see the module)."""

    def __init__(
        self,
        name: str,
        threads: int,
        max_queue: int,
        max_per_owner: int,
        *,
        one_per_owner: bool = False,
    ) -> None:
        self.name = name
        self.threads = threads
        self.max_queue = max_queue
        self.max_per_owner = max_per_owner
        self.one_per_owner = one_per_owner
        self._pool = ThreadPoolExecutor(threads, thread_name_prefix=f"c2rviz-{name}")
        self._queues: dict[object, deque[Job]] = {}
        self._turns: deque[object] = deque()  # owners with work waiting, next first
        self._urgent: deque[Job] = deque()
        self.running: list[Job] = []
        self.closed = False

    @property
    def waiting(self) -> int:
        """Jobs queued and not started."""
        return len(self._urgent) + sum(len(queue) for queue in self._queues.values())

    def jobs(self) -> Iterator[Job]:
        """Every job waiting, urgent first."""
        yield from self._urgent
        for queue in self._queues.values():
            yield from queue

    def supersede(self, key: Hashable) -> None:
        """A newer job with ``key`` comes: drop the waiting ones, ask a running one to stop."""
        for job in [job for job in self.jobs() if job.key == key]:
            self._remove(job)
            if not job.future.done():
                job.future.set_exception(Superseded())
        for job in self.running:
            if job.key == key and job.cancel is not None:
                job.cancel.set(SUPERSEDED)

    def cancel(self, owner: object, why: str) -> int:
        """Stop ``owner``'s jobs that can stop (those with a ``Cancel``): the waiting ones
        hear ``PlanCancelled`` now, the running ones when their search notices; how many."""
        count = 0
        for job in [job for job in self._queues.get(owner, ()) if job.cancel is not None]:
            self._remove(job)
            job.cancel.set(why)  # type: ignore[union-attr]
            if not job.future.done():
                job.future.set_exception(PlanCancelled(why))
            count += 1
        for job in self.running:
            if job.owner is owner and job.cancel is not None and not job.cancel():
                job.cancel.set(why)
                count += 1
        return count

    def submit(self, job: Job, urgent: bool = False) -> None:
        """Queue ``job`` (urgent: first of all).

        Raises:
            WorkerBusy: ``max_queue`` jobs wait, or ``max_per_owner`` of its owner's.
        """
        if urgent:
            self._urgent.append(job)  # (urgent jobs are keyed, one per robot at most)
        else:
            queue = self._queues.get(job.owner)
            if self.waiting >= self.max_queue:
                raise WorkerBusy(self.max_queue)
            if queue is not None and len(queue) >= self.max_per_owner:
                raise WorkerBusy(self.max_per_owner, mine=True)
            if queue is None:
                queue = self._queues[job.owner] = deque()
                self._turns.append(job.owner)
            queue.append(job)
        if job.cancel is not None:
            job.future.add_done_callback(functools.partial(_went_away, job.cancel))

    def pump(self, loop: asyncio.AbstractEventLoop) -> None:
        """Start waiting jobs while threads are free (urgent first, then owners in turn)."""
        while len(self.running) < self.threads and not self.closed:
            job = self._take()
            if job is None:
                return
            if job.future.done():  # cancelled while it waited (its client went away)
                continue
            self.running.append(job)
            done = loop.run_in_executor(self._pool, job.fn)
            done.add_done_callback(functools.partial(self._finished, loop, job))

    def _take(self) -> Job | None:
        """The next job to run: urgent first, then the next owner's first (round robin)."""
        if self._urgent:
            return self._urgent.popleft()
        busy = {job.owner for job in self.running} if self.one_per_owner else set()
        for _ in range(len(self._turns)):
            owner = self._turns.popleft()
            if owner is not None and owner in busy:
                self._turns.append(owner)  # its turn waits until its running job ends
                continue
            queue = self._queues[owner]
            job = queue.popleft()
            if queue:
                self._turns.append(owner)
            else:
                del self._queues[owner]
            return job
        return None

    def _remove(self, job: Job) -> None:
        if job in self._urgent:
            self._urgent.remove(job)
            return
        queue = self._queues.get(job.owner)
        if queue is not None and job in queue:
            queue.remove(job)
            if not queue:
                del self._queues[job.owner]
                self._turns.remove(job.owner)

    def _finished(
        self, loop: asyncio.AbstractEventLoop, job: Job, result: asyncio.Future[Any]
    ) -> None:
        self.running.remove(job)
        # read the outcome even when nobody awaits it any more (its client went away), or
        # asyncio logs "Future exception was never retrieved"
        error = None if result.cancelled() else result.exception()
        if not job.future.done():
            if result.cancelled():
                job.future.cancel()
            elif error is not None:
                job.future.set_exception(error)
            else:
                job.future.set_result(result.result())
        self.pump(loop)

    def close(self) -> None:
        """No more work: the waiting jobs are cancelled, the running ones asked to stop."""
        self.closed = True
        for job in list(self.jobs()):
            job.future.cancel()
        self._urgent.clear()
        self._queues.clear()
        self._turns.clear()
        for job in self.running:
            if job.cancel is not None:
                job.cancel.set(WENT_AWAY)
        self._pool.shutdown(wait=False, cancel_futures=True)


def _went_away(cancel: Cancel, future: asyncio.Future[Any]) -> None:
    """A job's awaiting reply was cancelled (its client closed): stop its search."""
    if future.cancelled():
        cancel.set(WENT_AWAY)
