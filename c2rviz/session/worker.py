"""CPU work off the event loop, fair to every client: IK solves, line plans, checks, plans.

The event loop serves every client; a solve, a collision check of a path or a plan
of tens of milliseconds run on it would stall them all. ``Worker.run(fn)`` queues
``fn`` and returns a future the handler awaits (its connection's reply waits;
every other client goes on). Two lanes (``lanes.Lane``) do the work:

- the **work lane**, one thread: IK solves, line plans, guarded checks, the
  guard's re-checks. Jobs there never overlap, so each robot's IK solver and the
  checkers kept in ``cache`` are used by one thread only;
- the **plan lane**, ``PLAN_THREADS`` threads: plans around obstacles (``plan``,
  a ``guard plan`` move), which may search for up to a minute. A plan never holds
  an IK solve or a guarded check behind it, and the plans of several clients
  search side by side, one per client at a time. A plan can be cancelled
  (``cancel(owner)``: ``stop``; its client closing; a newer plan with its key).
  A plan that searches longer than ``plan_process.THREAD_S`` goes on in a child
  process its thread forks (``plan_process``): OMPL's bindings hold the
  interpreter's lock in their C++, and its trees' rebuilds would stall the loop.

In each lane a job belongs to an owner (``owner=session``: one connection); every
owner has its own queue and the lane serves them in turn, so one client's long
queue delays only that client. Each lane is bounded (``max_queue`` jobs waiting
in all, ``MAX_PER_OWNER`` for one owner): one more is refused at once with
``WorkerBusy``. A job may carry a ``key``: a newer job with the same key replaces
the one still waiting (latest wins; its awaiting reply hears ``Superseded``), as
the page's sliders and handle drags want. An ``urgent`` job (re-checking a
running guarded motion) goes before the others.

Pinocchio and coal hold the interpreter's lock through each call, so the loop
waits for a worker thread until its call returns and the interpreter hands the
lock over; the worker lowers that hand-over interval to ``SWITCH_S`` (the
interpreter's default is 5 ms) and the checks run in small chunks
(``collision.batch.CHUNK``), so a bystander waits about a millisecond at most.
docs/limits.md has the measured figures.
"""

from __future__ import annotations

import asyncio
import os
import sys
from collections.abc import Callable, Hashable
from typing import Any, TypeVar

from ..ik.solver import IkSolver
from ..planning.errors import Cancel, PlanCancelled
from ..world.state import RobotState
from .lanes import Job, Lane

T = TypeVar("T")

MAX_QUEUE = 256  # jobs waiting for a lane at most (4 per client at the default 64 clients)
MAX_PER_OWNER = 16  # jobs of one owner (connection) waiting for a lane at most
PLAN_THREADS = 10  # plans searching at once (one per client), see docs/limits.md
PLAN_PROCESSES = hasattr(os, "fork")  # each plan in a child process (see plan_process.py)
SWITCH_S = 0.0005  # [s] the interpreter's thread switch interval while a worker exists


class Worker:
    """The work lane and the plan lane, and each robot's IK solver (see the module)."""

    def __init__(
        self,
        max_queue: int = MAX_QUEUE,
        plan_threads: int = PLAN_THREADS,
        plan_processes: bool = PLAN_PROCESSES,
    ) -> None:
        """Start the lanes' threads; lower the interpreter's switch interval (see the module).

        Args:
            max_queue: Jobs waiting for each lane at most (the running ones not counted).
            plan_threads: Plans searching at once.
            plan_processes: Let a plan that searches long go on in a child process
                forked by its plan lane thread (``plan_process.plan_job``), else on that thread.
        """
        self.plan_processes = plan_processes
        self.work = Lane("work", 1, max_queue, MAX_PER_OWNER)
        self.plans = Lane("plan", plan_threads, max_queue, MAX_PER_OWNER, one_per_owner=True)
        self._solvers: dict[str, IkSolver] = {}
        self._halted: dict[object, str] = {}  # owners whose plans are cancelled as they come
        self.cache: dict[Hashable, Any] = {}
        """What work-lane jobs keep between runs (checkers by robot); use it on that thread."""
        if sys.getswitchinterval() > SWITCH_S:
            sys.setswitchinterval(SWITCH_S)

    @property
    def max_queue(self) -> int:
        """Jobs waiting for the work lane at most."""
        return self.work.max_queue

    @max_queue.setter
    def max_queue(self, value: int) -> None:
        self.work.max_queue = value

    def ik_solver(self, state: RobotState) -> IkSolver:
        """The robot's IK solver (use it on the work lane's thread only)."""
        solver = self._solvers.get(state.name)
        if solver is None:
            solver = self._solvers[state.name] = IkSolver(state.robot)
        return solver

    @property
    def waiting(self) -> int:
        """Jobs queued and not started, in both lanes."""
        return self.work.waiting + self.plans.waiting

    def run(
        self,
        fn: Callable[[], T],
        *,
        key: Hashable | None = None,
        urgent: bool = False,
        owner: object = None,
    ) -> asyncio.Future[T]:
        """Queue ``fn`` for the work lane's thread; await the returned future on the loop.

        Args:
            fn: The work (it runs on the work lane's thread).
            key: A newer job with this key replaces this one while it waits.
            urgent: Run before the jobs waiting.
            owner: Whose job (a session); owners are served in turn.

        Raises:
            WorkerBusy: the lane's or the owner's queue is full (nothing is queued).
        """
        return self._submit(self.work, fn, key, urgent, owner, None)

    def plan(
        self,
        fn: Callable[[], T],
        *,
        key: Hashable | None = None,
        owner: object = None,
        cancel: Cancel | None = None,
    ) -> asyncio.Future[T]:
        """Queue ``fn``, a plan, for the plan lane; await the returned future on the loop.

        Args:
            fn: The plan (it runs on one of the plan lane's threads, which may fork a
                process for it: it keeps no state between runs, or keeps it per thread).
            key: A newer job with this key replaces this one, waiting or running.
            owner: Whose plan (a session): one plan of each owner searches at a time.
            cancel: What ``fn`` watches to stop early (``cancel(owner)``, a newer plan
                with ``key``, or this future cancelled: its client went away).

        Raises:
            WorkerBusy: the lane's or the owner's queue is full (nothing is queued).
        """
        return self._submit(self.plans, fn, key, False, owner, cancel)

    def _submit(
        self,
        lane: Lane,
        fn: Callable[[], T],
        key: Hashable | None,
        urgent: bool,
        owner: object,
        cancel: Cancel | None,
    ) -> asyncio.Future[T]:
        loop = asyncio.get_running_loop()
        future: asyncio.Future[T] = loop.create_future()
        if lane.closed:
            future.cancel()
            return future
        if lane is self.plans and owner in self._halted:
            future.set_exception(PlanCancelled(self._halted[owner]))
            return future
        if key is not None:
            self.work.supersede(key)
            self.plans.supersede(key)
        lane.submit(Job(fn, future, owner, key, cancel), urgent)
        lane.pump(loop)
        return future

    def cancel(self, owner: object, why: str) -> int:
        """Stop ``owner``'s plans, waiting or searching (``stop``, its client closing): they
        end with ``PlanCancelled``; how many were stopped."""
        return self.plans.cancel(owner, why)

    def planning(self, owner: object) -> bool:
        """``owner`` has a plan waiting or searching."""
        plans = self.plans
        return any(job.owner is owner for job in (*plans.running, *plans.jobs()))

    def halt(self, owner: object, why: str) -> None:
        """Stop ``owner``'s plans (``cancel``) and every plan it sends until ``go_on``: its
        client's ``stop`` or close was seen behind a reply that waits (``tcp_text``)."""
        self.cancel(owner, why)
        self._halted[owner] = why

    def go_on(self, owner: object) -> None:
        """``owner``'s plans run again (the ``stop`` that halted them has had its turn)."""
        self._halted.pop(owner, None)

    def close(self) -> None:
        """The program stops: no more work (queued work is dropped, plans are stopped)."""
        self.work.close()
        self.plans.close()
