"""Stopping a plan that is searching: ``Cancel``, the flag, and ``PlanCancelled``, the answer.

A plan may search for up to a minute on a worker thread. Its client may not wait
that long: it sends ``stop``, closes its connection, or sends a newer plan. The
loop then sets the plan's ``Cancel`` (``Cancel.set(why)``, from any thread); the
search looks at it between its steps (OMPL's termination condition, see
``ompl_planner``), and between the goals it tries, and the plan ends with
``PlanCancelled``: nothing moved.
"""

from __future__ import annotations

import threading

from c2rviz.errors import MotionInterrupted

__all__ = ["STOPPED", "SUPERSEDED", "WENT_AWAY", "Cancel", "PlanCancelled"]

STOPPED = "stopped"
SUPERSEDED = "a newer plan replaced it"
WENT_AWAY = "its client went away"


class PlanCancelled(MotionInterrupted):
    """A plan stopped before it found a path: nothing moved."""

    def __init__(self, why: str) -> None:
        super().__init__(f"plan cancelled ({why}); nothing moved")


class Cancel:
    """A flag that ends a plan's search, and why; set from any thread, read by the search.

    Calling it answers whether it is set, so it serves as OMPL's termination condition.
    """

    def __init__(self) -> None:
        self._event = threading.Event()
        self.why = ""

    def set(self, why: str) -> None:
        """Stop the search (the first reason given is kept)."""
        if not self._event.is_set():
            self.why = why
            self._event.set()

    def __call__(self) -> bool:
        return self._event.is_set()

    def check(self) -> None:
        """Raise ``PlanCancelled`` if set."""
        if self._event.is_set():
            raise PlanCancelled(self.why)
