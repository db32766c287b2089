"""Goals: where parts should end, and a score of how far each is. Pure, no state but theirs.

A goal names a part (``p1``) or a type (``type=gear``: any part of that type, each part
counting for one goal at most) and a pose in the world frame, with a tolerance in
position [m] and in angle [rad]. ``score`` pairs each goal with its part (a type goal:
the nearest part of its type not taken by an earlier goal, in the order the goals were
set) and says whether it is met and by how much it is off; a goal with no part is
missing. A part that is held, or still falling, does not meet its goal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError
from .parts import Part, PartError, Parts

__all__ = [
    "DEFAULT_TOL_M",
    "DEFAULT_TOL_RAD",
    "MAX_GOALS",
    "Goal",
    "GoalBook",
    "GoalResult",
    "TooManyGoals",
    "score",
]

DEFAULT_TOL_M = 0.005
"""A goal's position tolerance when none is given [m]."""
DEFAULT_TOL_RAD = math.radians(5.0)
"""A goal's angle tolerance when none is given [rad]."""
MAX_GOALS = 100
"""Goals at once."""
TYPE_PREFIX = "type="


class TooManyGoals(C2rvizError):
    def __init__(self, limit: int) -> None:
        super().__init__(f"there are already {limit} goals, the limit; remove one first")


@dataclass(frozen=True)
class Goal:
    """Where a part (``name``) or a part of a type (``type=T``) should end.

    Attributes:
        key: A part's name, or ``type=T``.
        pose: The pose in the world frame.
        tol_m: How far off its position may be [m].
        tol_rad: How far off its orientation may be [rad].
    """

    key: str
    pose: pin.SE3
    tol_m: float = DEFAULT_TOL_M
    tol_rad: float = DEFAULT_TOL_RAD

    @property
    def kind(self) -> str | None:
        """The type it asks for, or None for a named part."""
        return self.key[len(TYPE_PREFIX) :] if self.key.startswith(TYPE_PREFIX) else None


@dataclass(frozen=True)
class GoalResult:
    """One goal scored: its part (None: missing), how far off [m, rad], and whether met."""

    goal: Goal
    part: str | None
    off_m: float = math.inf
    off_rad: float = math.inf
    met: bool = False


def off(pose: pin.SE3, goal: pin.SE3) -> tuple[float, float]:
    """How far ``pose`` is from ``goal``: distance [m] and angle [rad]."""
    distance = float(np.linalg.norm(pose.translation - goal.translation))
    angle = float(np.linalg.norm(pin.log3(goal.rotation.T @ pose.rotation)))
    return distance, angle


def score(goals: Sequence[Goal], parts: Sequence[Part]) -> list[GoalResult]:
    """Each goal with its part and how far off it is (see the module)."""
    by_name = {part.name: part for part in parts}
    named = {goal.key for goal in goals if goal.kind is None}
    used: set[str] = set()
    results = []
    for goal in goals:
        kind = goal.kind
        if kind is None:
            part = by_name.get(goal.key)
        else:
            candidates = [
                p for p in parts if p.kind == kind and p.name not in used and p.name not in named
            ]
            part = min(candidates, key=lambda p: off(p.pose, goal.pose)[0], default=None)
        if part is None:
            results.append(GoalResult(goal, None))
            continue
        used.add(part.name)
        distance, angle = off(part.pose, goal.pose)
        met = (
            distance <= goal.tol_m
            and angle <= goal.tol_rad
            and part.holder is None
            and not part.falling
        )
        results.append(GoalResult(goal, part.name, distance, angle, met))
    return results


class GoalBook:
    """The goals of a world, by key, in the order they were first set."""

    def __init__(self, max_goals: int = MAX_GOALS) -> None:
        self.max_goals = max_goals
        self._goals: dict[str, Goal] = {}

    def set(self, goal: Goal, parts: Parts) -> None:
        """Add or replace ``goal``; one for a named part that is not in ``parts`` is refused
        (``UnknownPart``; a type goal with no part of its type counts as missing)."""
        if goal.kind is None:
            parts.get(goal.key)
        if goal.key not in self._goals and len(self._goals) >= self.max_goals:
            raise TooManyGoals(self.max_goals)
        self._goals[goal.key] = goal

    def remove(self, key: str) -> None:
        """Remove one goal (``all``: every one)."""
        if key == "all":
            self._goals.clear()
        elif self._goals.pop(key, None) is None:
            have = ", ".join(self._goals) or "none"
            raise PartError(f"no goal for {key!r} (goals: {have})")

    def all(self) -> list[Goal]:
        return list(self._goals.values())
