"""The planning errors: bad settings, ends that collide or lie outside the limits, no path,
a plan cancelled; and ``Cancel``, the flag that stops a plan.

Each builds its one-line message and keeps its fields; all are ``C2rvizError``
subclasses, so the server answers them with ``error: <message>``.

Stopping a plan that is searching: ``Cancel``, the flag, and ``PlanCancelled``, the
answer. A plan may search for up to a minute on a worker thread. Its client may not wait
that long: it sends ``stop``, closes its connection, or sends a newer plan. The
loop then sets the plan's ``Cancel`` (``Cancel.set(why)``, from any thread); the
search looks at it between its steps (OMPL's termination condition, see
``ompl_planner``), and between the goals it tries, and the plan ends with
``PlanCancelled``: nothing moved.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from c2rviz.errors import C2rvizError, MotionInterrupted

Pair = tuple[str, str]


class PlanningError(C2rvizError):
    """Root of the planning errors."""


class BadPlanningSetting(PlanningError):
    """A planning setting (step, timeout, seed, size) that is NaN, out of range or malformed."""

    def __init__(self, key: str, value: object, valid: str) -> None:
        self.key = key
        self.value = value
        self.valid = valid
        super().__init__(f"{key} = {value!r} is not valid: {valid}")


def checked_setting(key: str, value: object, low: float, high: float, unit: str) -> float:
    """``value`` as a float, or ``BadPlanningSetting`` unless a finite number in ``low..high``."""
    valid = f"give a number from {low:g} to {high:g} {unit}"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise BadPlanningSetting(key, value, valid)
    number = float(value)
    if not (math.isfinite(number) and low <= number <= high):
        raise BadPlanningSetting(key, value, valid)
    return number


class StartCollides(PlanningError):
    """The start configuration is already in collision."""

    def __init__(self, pair: Pair | None) -> None:
        self.pair = pair
        what = f"{pair[0]} touches {pair[1]}" if pair else "it is in collision"
        super().__init__(f"the start collides: {what} (move it free first)")


class GoalCollides(PlanningError):
    """The goal configuration is in collision."""

    def __init__(self, pair: Pair | None) -> None:
        self.pair = pair
        what = f"{pair[0]} would touch {pair[1]}" if pair else "it is in collision"
        super().__init__(f"the goal collides: {what}")


class OutOfLimits(PlanningError):
    """A start or goal value outside the bounds planned in [rad or m]."""

    def __init__(self, which: str, index: int, value: float, lower: float, upper: float) -> None:
        self.which = which
        self.index = index
        self.value = value
        self.lower = lower
        self.upper = upper
        super().__init__(
            f"the {which}'s joint {index} = {value:.6g} is outside its limits "
            f"{lower:.6g}..{upper:.6g} (rad or m)"
        )


class NoPathFound(PlanningError):
    """RRT-Connect found no path within the time limit."""

    def __init__(self, timeout_s: float, states: int) -> None:
        self.timeout_s = timeout_s
        self.states = states
        super().__init__(f"no path found in {timeout_s:.1f} s ({states} states)")


class PathCheckFailed(PlanningError):
    """The final edge-by-edge check refused the simplified path (not expected)."""

    def __init__(self, edge: int) -> None:
        self.edge = edge
        super().__init__(f"the planned path's edge {edge} collides at the check resolution")


class NoWayAround(PlanningError):
    """A guarded move (``guard plan``) whose straight path is blocked and no plan goes round."""

    def __init__(self, blocked: str, why: str) -> None:
        self.blocked = blocked
        self.why = why
        super().__init__(f"{blocked}, and no way around it: {why}")


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
