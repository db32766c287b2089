"""CPU work off the event loop: IK solves and line plans, one at a time, on one thread.

The event loop serves every client; a solve of tens of milliseconds run on it would
stall them all. ``Worker.run(fn)`` hands ``fn`` to the worker's thread and returns a
future the handler awaits (its connection's reply waits; every other client goes on).
Work never overlaps, so each robot's IK solver is used by one thread only.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from ..ik.solver import IkSolver
from ..world.state import RobotState

__all__ = ["Worker"]

T = TypeVar("T")


class Worker:
    """One thread for CPU work, and each robot's IK solver (built on first use)."""

    def __init__(self) -> None:
        self._thread = ThreadPoolExecutor(1, thread_name_prefix="c2rviz-work")
        self._solvers: dict[str, IkSolver] = {}

    def ik_solver(self, state: RobotState) -> IkSolver:
        """The robot's IK solver (use it on the worker's thread only)."""
        solver = self._solvers.get(state.name)
        if solver is None:
            solver = self._solvers[state.name] = IkSolver(state.robot)
        return solver

    def run(self, fn: Callable[[], T]) -> asyncio.Future[T]:
        """Run ``fn`` on the worker's thread; await the returned future on the loop."""
        return asyncio.get_running_loop().run_in_executor(self._thread, fn)

    def close(self) -> None:
        """The program stops: no more work (queued work is dropped)."""
        self._thread.shutdown(wait=False, cancel_futures=True)
