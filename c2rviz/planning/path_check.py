"""The guard's check of a path: the first point that collides, leaving a contact allowed.

A guarded move is checked along the path the arm will take (``path_points``: each
edge of the polyline at the checker's resolution, in order). ``first_blocked``
finds its first point in collision and the pair. Pairs already in contact where
the move starts (``allowed``) do not block it while they stay in contact: a move
that leaves a contact goes; but once such a pair is apart, touching again blocks
the move like any other pair. So a guard that let the arm end touching something
(a new object put on it) does not refuse every move after, only the ones that
push on.
"""

from __future__ import annotations

from collections.abc import Collection

import numpy as np

from c2rviz.collision import Pair

from .edge_resolution import coarse_first
from .validity import ValidityChecker

__all__ = ["first_blocked", "path_points"]


def path_points(checker: ValidityChecker, waypoints: np.ndarray) -> np.ndarray:
    """Every point checked along the polyline ``waypoints`` (rows) [rad or m], in order,
    each edge at ``checker``'s resolution (a single row: itself)."""
    waypoints = np.atleast_2d(np.asarray(waypoints, dtype=float))
    if len(waypoints) == 1:
        return waypoints
    parts = [waypoints[:1]]
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        parts.append(checker.edge_points(a, b)[1:])
    return np.vstack(parts)


def first_blocked(
    checker: ValidityChecker, points: np.ndarray, allowed: Collection[Pair] = ()
) -> tuple[int, Pair] | None:
    """The index of the first of ``points`` (rows, in order) that blocks a move, and the
    pair; None when none does.

    A point blocks when a pair not in ``allowed`` collides there, or a pair of
    ``allowed`` collides there after it was once apart (see the module).
    """
    points = np.atleast_2d(np.asarray(points, dtype=float))
    allowed = frozenset(allowed)
    strict = checker.variant(without=allowed) if allowed else checker
    found: list[tuple[int, Pair]] = []
    if strict.first_invalid(points[coarse_first(len(points))]) is not None:  # quick: any?
        index = strict.first_invalid(points)  # then the first, in order
        if index is not None:
            pair = strict.describe(points[index])
            found.append((index, pair if pair is not None else ("?", "?")))
    for pair in sorted(allowed):
        hits = checker.variant(only=(pair,)).batch.hits(points)
        if np.all(hits):
            continue
        cleared = int(np.argmin(hits))
        again = np.flatnonzero(hits[cleared:])
        if again.size:
            found.append((cleared + int(again[0]), pair))
    return min(found) if found else None
