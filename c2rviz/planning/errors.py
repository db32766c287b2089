"""The planning errors: bad settings, ends that collide or lie outside the limits, no path.

Each builds its one-line message and keeps its fields; all are ``C2rvizError``
subclasses, so the server answers them with ``error: <message>``.
"""

from __future__ import annotations

import math

import numpy as np

from c2rviz.errors import C2rvizError

__all__ = [
    "BadPlanningSetting",
    "GoalCollides",
    "NoPathFound",
    "NoWayAround",
    "OutOfLimits",
    "PathCheckFailed",
    "PlanningError",
    "StartCollides",
    "checked_setting",
]

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
