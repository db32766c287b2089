"""CPU work off the event loop: IK solves, line plans, guarded checks and paths, one at a time.

The event loop serves every client; a solve, a collision check of a path or a plan
of tens of milliseconds run on it would stall them all. ``Worker.run(fn)`` queues
``fn`` for the worker's one thread and returns a future the handler awaits (its
connection's reply waits; every other client goes on). Work never overlaps, so
each robot's IK solver and the checkers cached for the worker are used by one
thread only.

The queue is bounded (``max_queue`` jobs waiting): one more is refused at once
with ``WorkerBusy``, so a flood of heavy commands costs a clear error, not memory
or minutes of delay. A job may carry a ``key``: a newer job with the same key
replaces the one still waiting (latest wins; its awaiting reply hears
``Superseded``), as the page's sliders and handle drags want. An ``urgent`` job
(re-checking a running guarded motion) goes before the others.

Pinocchio and coal hold the interpreter's lock through each call, so the loop
waits for the worker's thread until its call returns and the interpreter hands
the lock over; the worker lowers that hand-over interval to ``SWITCH_S`` (the
interpreter's default is 5 ms) and the checks run in small chunks
(``collision.batch.CHUNK``), so a bystander waits about a millisecond at most.
"""

from __future__ import annotations

import asyncio
import functools
import sys
from collections import deque
from collections.abc import Callable, Hashable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, TypeVar

from ..errors import C2rvizError, MotionInterrupted
from ..ik.solver import IkSolver
from ..world.state import RobotState

__all__ = ["MAX_QUEUE", "SWITCH_S", "Superseded", "Worker", "WorkerBusy"]

T = TypeVar("T")

MAX_QUEUE = 256  # jobs waiting for the worker at most (4 per client at the default 64 clients)
SWITCH_S = 0.0005  # [s] the interpreter's thread switch interval while a worker exists


class WorkerBusy(C2rvizError):
    """The worker's queue is full: the command is refused, nothing changed."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(
            f"the server is busy: {limit} heavy commands (checks, IK, plans) wait already, "
            "its limit; try again"
        )


class Superseded(MotionInterrupted):
    """A job replaced by a newer one with the same key before it ran."""

    def __init__(self) -> None:
        super().__init__("superseded by a newer command before it was checked")


@dataclass(eq=False)
class _Job:
    fn: Callable[[], Any]
    future: asyncio.Future[Any]
    key: Hashable | None = None


class Worker:
    """One thread for CPU work, a bounded queue in front of it, and each robot's IK solver."""

    def __init__(self, max_queue: int = MAX_QUEUE) -> None:
        """Start the thread; lower the interpreter's switch interval (see the module).

        Args:
            max_queue: Jobs waiting at most (the one running not counted).
        """
        self.max_queue = max_queue
        self._thread = ThreadPoolExecutor(1, thread_name_prefix="c2rviz-work")
        self._solvers: dict[str, IkSolver] = {}
        self._waiting: deque[_Job] = deque()
        self._running: _Job | None = None
        self._closed = False
        self.cache: dict[Hashable, Any] = {}
        """What jobs keep between runs (checkers by robot); use it on the worker's thread."""
        if sys.getswitchinterval() > SWITCH_S:
            sys.setswitchinterval(SWITCH_S)

    def ik_solver(self, state: RobotState) -> IkSolver:
        """The robot's IK solver (use it on the worker's thread only)."""
        solver = self._solvers.get(state.name)
        if solver is None:
            solver = self._solvers[state.name] = IkSolver(state.robot)
        return solver

    @property
    def waiting(self) -> int:
        """Jobs queued and not started."""
        return len(self._waiting)

    def run(
        self, fn: Callable[[], T], *, key: Hashable | None = None, urgent: bool = False
    ) -> asyncio.Future[T]:
        """Queue ``fn`` for the worker's thread; await the returned future on the loop.

        Args:
            fn: The work (it runs on the worker's thread).
            key: A newer job with this key replaces this one while it waits.
            urgent: Run before the jobs waiting.

        Raises:
            WorkerBusy: ``max_queue`` jobs wait already (nothing is queued).
        """
        loop = asyncio.get_running_loop()
        future: asyncio.Future[T] = loop.create_future()
        if self._closed:
            future.cancel()
            return future
        if key is not None:
            for job in list(self._waiting):
                if job.key == key:
                    self._waiting.remove(job)
                    if not job.future.done():
                        job.future.set_exception(Superseded())
        if not urgent and len(self._waiting) >= self.max_queue:
            raise WorkerBusy(self.max_queue)  # (urgent jobs are keyed, one per robot at most)
        job = _Job(fn, future, key)
        if urgent:
            self._waiting.appendleft(job)
        else:
            self._waiting.append(job)
        self._next(loop)
        return future

    def _next(self, loop: asyncio.AbstractEventLoop) -> None:
        """Start the next job that is still wanted, if none runs."""
        while self._running is None and self._waiting and not self._closed:
            job = self._waiting.popleft()
            if job.future.done():  # cancelled while it waited (its client went away)
                continue
            self._running = job
            done = loop.run_in_executor(self._thread, job.fn)
            done.add_done_callback(functools.partial(self._finished, loop, job))

    def _finished(
        self, loop: asyncio.AbstractEventLoop, job: _Job, result: asyncio.Future[Any]
    ) -> None:
        self._running = None
        if not job.future.done():
            if result.cancelled():
                job.future.cancel()
            elif (error := result.exception()) is not None:
                job.future.set_exception(error)
            else:
                job.future.set_result(result.result())
        self._next(loop)

    def close(self) -> None:
        """The program stops: no more work (queued work is dropped)."""
        self._closed = True
        for job in self._waiting:
            job.future.cancel()
        self._waiting.clear()
        self._thread.shutdown(wait=False, cancel_futures=True)
