"""A collision-free joint-space path between two configurations, with OMPL.

``plan_path`` tries the direct edge start -> goal first (when it is free, that
is the path, no OMPL at all). Otherwise it plans in the box of bounds given
(OMPL's ``RealVectorStateSpace``) with RRT-Connect (extensions of at most 1 rad:
OMPL's default, a fifth of the box, made detours 1.5 times longer on the
benchmark's scenes), shortens the path found (``_shorten``), and makes sure
every edge of the result was checked at the resolution: an edge the shortening
found free (same ends, same direction) counts, any other is checked then. The
validity of a state and of an edge are the caller's (``ValidityChecker``'s
``is_valid`` and ``check_edge`` through ``plan_for``; or any ``is_valid`` with
a joint step).

Shortening: OMPL's ``simplifySolution`` (shortcuts, B-spline smoothing,
vertex reduction, to convergence) costs here 5 to 10 times the search itself,
because each edge it tries is checked at 1 degree / 5 mm of tool travel; and its
B-spline smoothing adds corners, each a stop of the timed motion
(``timing.py``). So it runs OMPL's shortcutting pieces once each
(``reduceVertices``, ``partialShortcutPath``, ``collapseCloseVertices``), then a
pass of our own that slides each corner towards its neighbours' midpoint while
both edges stay free (smoothing without adding corners).

Seeded randomness: OMPL draws every sampler's seed from one process-wide seed
generator; ``plan_path`` reseeds it before it builds the planner, so a seed and
the same checks give the same path whatever ran before. The search stops at its
first solution, so the time limit does not change the path. Several plans may
search at once (each on its own thread): a lock is held while a plan's random
sources are drawn from that generator (its seeding, the sampler, the
simplifier), not while it searches; OMPL's log is silenced while any plan runs.

Cancellation: the search also stops when ``cancel`` (a ``cancel.Cancel``) is set,
looked at between RRT-Connect's steps (OMPL's termination condition), and the
plan ends with ``PlanCancelled``.
"""

from __future__ import annotations

import logging
import os
import secrets
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from .errors import (
    BadPlanningSetting,
    Cancel,
    GoalCollides,
    NoPathFound,
    OutOfLimits,
    PathCheckFailed,
    StartCollides,
    checked_setting,
)
from .validity import EdgeResolution, ValidityChecker, coarse_first

log = logging.getLogger("c2rviz.planning")


MAX_TIMEOUT_S = 60.0  # [s] longest search accepted
_MIN_TIMEOUT_S = 1e-3  # [s]
SEEDS = 2**31 - 1  # seeds are 0 .. SEEDS - 1
_SLIDES = (1.0, 0.5, 0.25)  # fractions of the way to the neighbours' midpoint tried
_SWEEPS = 4  # most passes of corner sliding
_RANGE_RAD = 1.0  # [rad] RRT-Connect's longest extension (OMPL's default: a fifth of the box)
_LOCK = threading.Lock()  # OMPL's seed generator and log level are process-wide
_quiet = [0, ou.LOG_INFO]  # plans running, OMPL's log level before the first (under _LOCK)


def fork_lock() -> threading.Lock:
    """Hold it around a ``fork``: no thread is drawing OMPL's seeds meanwhile."""
    return _LOCK


def _after_fork() -> None:
    """A forked child (a plan's process) starts with a lock of its own, not a copy."""
    global _LOCK
    _LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork)

EdgeCheck = Callable[[np.ndarray, np.ndarray], tuple[bool, int]]
"""``(q0, q1) -> (free, configurations checked)``; ``q0`` is taken as already checked."""


@dataclass(frozen=True)
class PlannedPath:
    """A collision-free polyline in joint space.

    Attributes:
        waypoints: The corners, start and goal included, one row each [rad or m].
        length_rad: Its length in joint space, the edges' Euclidean norms added
            up [rad, metres counted as radians for prismatic joints].
        states_checked: Configurations checked while planning.
        planning_s: Wall time spent, checks included [s].
        seed: The seed that gives this path again.
    """

    waypoints: np.ndarray
    length_rad: float
    states_checked: int
    planning_s: float
    seed: int


class _Counted:
    """The caller's checks, with a count of the configurations they looked at.

    An edge found free is remembered by its exact ends and direction, so the
    final check does not check again what the shortening just checked: its
    answer is a function of the two ends (the checks keep no history).
    """

    def __init__(self, is_valid: Callable[[np.ndarray], bool], edge: EdgeCheck) -> None:
        self._is_valid = is_valid
        self._edge = edge
        self._free: set[tuple[bytes, bytes]] = set()
        self.count = 0

    def state(self, q: np.ndarray) -> bool:
        self.count += 1
        return bool(self._is_valid(q))

    def edge(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        key = (q0.tobytes(), q1.tobytes())
        if key in self._free:
            return True
        free, checked = self._edge(q0, q1)
        self.count += checked
        if free:
            self._free.add(key)
        return free


def _grid_check(is_valid: Callable[[np.ndarray], bool], resolution: EdgeResolution) -> EdgeCheck:
    """An edge check from a state check: the joint grid, far end first, coarse to fine."""

    def check(q0: np.ndarray, q1: np.ndarray) -> tuple[bool, int]:
        rest = resolution.grid(q0, q1)[1:]
        for checked, k in enumerate(coarse_first(len(rest)), start=1):
            if not is_valid(rest[k]):
                return False, checked
        return True, len(rest)

    return check


class _EdgeValidator(ob.MotionValidator):
    """OMPL's edge check, answered by ours."""

    def __init__(self, info: ob.SpaceInformation, n: int, checks: _Counted) -> None:
        super().__init__(info)
        self._n = n
        self._checks = checks

    def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
        n = self._n
        return self._checks.edge(np.array(s1[0:n]), np.array(s2[0:n]))


def _seed(seed: int | None) -> int:
    if seed is None:
        return secrets.randbelow(SEEDS)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < SEEDS:
        raise BadPlanningSetting("seed", seed, f"give a whole number from 0 to {SEEDS - 1}")
    return int(seed)


def plan_path(
    start: Sequence[float],
    goal: Sequence[float],
    lower: Sequence[float],
    upper: Sequence[float],
    is_valid: Callable[[np.ndarray], bool],
    *,
    max_step: Sequence[float] | None = None,
    check_edge: EdgeCheck | None = None,
    describe: Callable[[np.ndarray], tuple[str, str] | None] | None = None,
    timeout_s: float = 1.0,
    seed: int | None = None,
    cancel: Cancel | None = None,
) -> PlannedPath:
    """A collision-free path from ``start`` to ``goal`` within ``lower..upper``.

    Args:
        start: Chain values to leave from [rad or m].
        goal: Chain values to arrive at [rad or m].
        lower: Lower bound of each joint in the search [rad or m].
        upper: Upper bound of each joint in the search [rad or m].
        is_valid: True when a configuration is free.
        max_step: Most a joint moves between two checks of an edge, per joint
            [rad or m] (edges are then checked with ``is_valid``).
        check_edge: An edge check of the caller's (``ValidityChecker.check_edge``),
            instead of ``max_step``; give exactly one of the two.
        describe: The first colliding pair at a configuration (for the errors).
        timeout_s: Most time RRT-Connect searches [s], in (0, 60].
        seed: Seed of the search (a fresh one if None; the result says which).
        cancel: Stops the search when set (see the module).

    Raises:
        BadPlanningSetting: a NaN, non-positive or huge timeout, step or seed,
            or ends and bounds of the wrong length.
        OutOfLimits: the start or goal is outside the bounds.
        StartCollides, GoalCollides: either end is in collision (names the pair).
        NoPathFound: RRT-Connect found nothing in ``timeout_s``.
        PlanCancelled: ``cancel`` was set before a path was found.
        PathCheckFailed: the shortened path failed its final check (not expected).
    """
    began = time.perf_counter()
    timeout = checked_setting("timeout_s", timeout_s, _MIN_TIMEOUT_S, MAX_TIMEOUT_S, "s")
    chosen = _seed(seed)
    if (max_step is None) == (check_edge is None):
        raise BadPlanningSetting("max_step", max_step, "give max_step or check_edge, not both")
    if check_edge is None:
        check_edge = _grid_check(is_valid, EdgeResolution(tuple(max_step or ())))
    a, b, low, high = (np.asarray(x, dtype=float) for x in (start, goal, lower, upper))
    n = len(a)
    steps = np.asarray(max_step if max_step is not None else np.zeros(n))
    for key, values in (("goal", b), ("lower", low), ("upper", high), ("max_step", steps)):
        if values.shape != (n,):
            raise BadPlanningSetting(key, tuple(values.ravel()), f"give {n} values, like start")
    for which, q in (("start", a), ("goal", b)):
        for i, (x, lo, hi) in enumerate(zip(q, low, high)):
            if not lo <= x <= hi:  # also refuses NaN
                raise OutOfLimits(which, i, float(x), float(lo), float(hi))
    checks = _Counted(is_valid, check_edge)
    if not checks.state(a):
        raise StartCollides(describe(a) if describe else None)
    if not checks.state(b):
        raise GoalCollides(describe(b) if describe else None)
    if checks.edge(a, b):
        waypoints = np.array([a, b])
    else:
        found = _rrt_connect(a, b, low, high, checks, timeout, chosen, cancel)
        if found is None:  # raised here, so that no OMPL object lives on in its traceback
            if cancel is not None:
                cancel.check()
            raise NoPathFound(timeout, checks.count)
        waypoints = _shorten(found, checks)
        failed = _first_failed_edge(waypoints, checks)
        if failed is not None and _first_failed_edge(found, checks) is None:
            log.warning("planning: the shortened path's edge %d failed its check", failed)
            waypoints = found  # OMPL's own path passes: take it, longer but checked
        elif failed is not None:
            raise PathCheckFailed(failed)
    length = float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)))
    return PlannedPath(waypoints, length, checks.count, time.perf_counter() - began, chosen)


def _rrt_connect(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    checks: _Counted,
    timeout_s: float,
    seed: int,
    cancel: Cancel | None = None,
) -> np.ndarray | None:
    """RRT-Connect's path from ``start`` to ``goal`` after OMPL's shortcutting (rows), or
    None if it found none in ``timeout_s`` (or ``cancel`` was set)."""
    n = len(start)
    with _LOCK:
        if _quiet[0] == 0:
            _quiet[1] = ou.getLogLevel()
            ou.setLogLevel(ou.LOG_NONE)
        _quiet[0] += 1
    try:
        return _search(start, goal, lower, upper, checks, timeout_s, seed, cancel, n)
    finally:
        with _LOCK:
            _quiet[0] -= 1
            if _quiet[0] == 0:
                ou.setLogLevel(_quiet[1])


def _search(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    checks: _Counted,
    timeout_s: float,
    seed: int,
    cancel: Cancel | None,
    n: int,
) -> np.ndarray | None:
    """``_rrt_connect``'s search, with OMPL's log silenced."""
    with _LOCK:  # every random source of this plan drawn in order from the seed
        ou.RNG.setSeed(seed + 1)  # OMPL's seeds start at 1; before any sampler exists
        space = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for i in range(n):
            bounds.setLow(i, float(lower[i]))
            bounds.setHigh(i, float(max(upper[i], lower[i] + 1e-9)))
        space.setBounds(bounds)
        setup = og.SimpleSetup(space)
        setup.setStateValidityChecker(lambda state: checks.state(np.array(state[0:n])))
        info = setup.getSpaceInformation()
        info.setMotionValidator(_EdgeValidator(info, n, checks))
        ends = []
        for values in (start, goal):
            state = space.allocState()
            state[0:n] = values.tolist()
            ends.append(state)
        setup.setStartAndGoalStates(ends[0], ends[1])
        planner = og.RRTConnect(info)
        planner.setRange(_RANGE_RAD)  # local detours, shorter paths (see the benchmark)
        setup.setPlanner(planner)
        setup.solve(ob.PlannerTerminationCondition(lambda: True))  # its sampler: no search
        simplifier = og.PathSimplifier(info)  # (drawn after the sampler, as before)
    began = time.perf_counter()
    timed = ob.timedPlannerTerminationCondition(timeout_s)
    if cancel is None:
        setup.solve(timed)
    else:
        stop = ob.PlannerTerminationCondition(cancel)
        setup.solve(ob.plannerOrTerminationCondition(timed, stop))
    log.debug("planning: searched %.3f s", time.perf_counter() - began)
    if not setup.haveExactSolutionPath():
        return None
    path = setup.getSolutionPath()
    simplifier.reduceVertices(path)
    simplifier.partialShortcutPath(path)
    simplifier.collapseCloseVertices(path)
    rows = [path.getState(k)[0:n] for k in range(path.getStateCount())]
    waypoints = np.clip(np.array(rows, dtype=float), lower, upper)  # a zero-width joint
    waypoints[0], waypoints[-1] = start, goal  # exact ends, not OMPL's copies
    return waypoints


def _first_failed_edge(waypoints: np.ndarray, checks: _Counted) -> int | None:
    """The index of the first edge of ``waypoints`` that fails its check, or None."""
    for k in range(len(waypoints) - 1):
        if not checks.edge(waypoints[k], waypoints[k + 1]):
            return k
    return None


def _shorten(waypoints: np.ndarray, checks: _Counted) -> np.ndarray:
    """Fewer and shorter corners: each vertex to the farthest one it sees, then each
    corner slid towards its neighbours' midpoint while both its edges stay free."""
    kept, i = [0], 0
    while i < len(waypoints) - 1:
        j = len(waypoints) - 1
        while j > i + 1 and not checks.edge(waypoints[i], waypoints[j]):
            j -= 1
        kept.append(j)
        i = j
    path = waypoints[kept].copy()
    for _ in range(_SWEEPS):
        moved = False
        for k in range(1, len(path) - 1):
            before, corner, after = path[k - 1], path[k], path[k + 1]
            target = (before + after) / 2 - corner
            for fraction in _SLIDES:
                moved_to = corner + fraction * target
                if checks.edge(before, moved_to) and checks.edge(moved_to, after):
                    path[k] = moved_to
                    moved = True
                    break
        if not moved:
            break
    keep = np.concatenate(([True], np.any(np.diff(path, axis=0) != 0, axis=1)))
    return path[keep]


def plan_for(
    checker: ValidityChecker,
    start: Sequence[float],
    goal: Sequence[float],
    *,
    timeout_s: float = 1.0,
    seed: int | None = None,
    cancel: Cancel | None = None,
) -> PlannedPath:
    """``plan_path`` for one robot: ``checker``'s bounds, state and edge checks, and pairs."""
    lower, upper = checker.bounds(start, goal)
    return plan_path(
        start,
        goal,
        lower,
        upper,
        checker.is_valid,
        check_edge=checker.check_edge,
        describe=checker.describe,
        timeout_s=timeout_s,
        seed=seed,
        cancel=cancel,
    )
