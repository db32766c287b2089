"""A move checked, or planned around obstacles, off the event loop: ``MoveChecker``.

The session takes a snapshot of what a move is checked against on the event loop
(``MoveRequest``: the robot's collision checks as they are, the other robots'
shapes where they stand, the start and the goal) and hands it to the worker's
thread, where ``MoveChecker.check`` answers with the path the arm may take
(``CheckedMove``) or refuses:

- ``target_only`` (a move shown at once): the goal alone is checked;
- otherwise the path (the straight joint-space segment, or the polyline given)
  at the checker's resolution, first point first (``first_blocked``, below:
  contacts at the start may be left, not pushed into); with several goals (a guarded
  ``rand``'s free draws) the first with a free straight path is taken, and if none
  has one the first goal's contact is the answer;
- ``plan="blocked"`` (``guard plan``): a blocked straight path is planned around;
  ``plan="always"`` (``plan``): every goal is planned (the direct edge first),
  trying the goals given in order (several IK answers of a pose) until one plans.

The checkers are kept between jobs (one per robot, rebuilt when its workcell, the
other robots or the resolution change), so a stream of guarded commands costs a
check each, not a checker each.

The guard's check of a path finds the first point that collides, leaving a contact
allowed. A guarded move is checked along the path the arm will take (``path_points``: each
edge of the polyline at the checker's resolution, in order). ``first_blocked``
finds its first point in collision and the pair. Pairs already in contact where
the move starts (``allowed``) do not block it while they stay in contact: a move
that leaves a contact goes; but once such a pair is apart, touching again blocks
the move like any other pair. So a guard that let the arm end touching something
(a new object put on it) does not refuse every move after, only the ones that
push on.

Several IK solutions of one tool pose (``goal_candidates``), for a planner to choose the
one it can reach (``plan pose``): a redundant arm, or one with elbow and wrist flips, puts
its tool at a pose in several ways; the one nearest the arm may sit behind an obstacle
while another is free and reachable. ``goal_candidates`` gives the solver's own answer
(the one ``ik`` and ``moveto`` use) first, then distinct answers from the solver's
restarts (its stored seed configurations closest to the target), nearest the arm first.
Use it on the solver's thread.
"""

from __future__ import annotations

import time
from collections.abc import Collection, Hashable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from c2rviz.collision import CheckGeometry, CollisionModel, Pair, PlacedShape
from c2rviz.errors import PathCollides
from c2rviz.ik import IkSolver, Target
from c2rviz.ik.chain import goal_in_world

from .errors import Cancel, GoalCollides, NoPathFound, NoWayAround, PlanningError
from .ompl_planner import PlannedPath, plan_for
from .validity import EdgeResolution, ValidityChecker, coarse_first

PLAN_MODES = ("never", "blocked", "always")

OtherAt = tuple[str, tuple[float, ...] | None, bytes]
"""Another robot when a request was made: name, joints if still (else None), origin's bytes."""


@dataclass(frozen=True, eq=False)
class MoveRequest:
    """A move to check off the event loop, and what it is checked against.

    Attributes:
        collision: The robot's collision model.
        source: Its checks when the request was made (``check_geometry()``).
        others: The other robots' shapes where they stood, placed in the cell.
        others_at: Each other robot: its name, its joints [rad or m] if it stood
            still (None if it moved) and its place (the bytes of its origin), so the
            caller can tell when ``others`` changed.
        origin: Where this robot's root stands in the cell.
        resolution: How finely edges are checked.
        start: Where the move starts, at rest [rad or m].
        goals: Where it may end, in order of preference [rad or m].
        path: A polyline to check instead of the straight segment (rows, start first).
        target_only: Check the first goal alone (a move shown at once).
        plan: ``never``, ``blocked`` (plan around a blocked straight path) or ``always``.
        timeout_s: Most time a plan may search [s].
        seed: The planner's seed (None: a fresh one).
        cancel: Stops a plan's search when set (None: only its time limit does).
        spent: A search of this move before this one: its seconds and states, counted
            in the time limit and in the states a refusal reports.
    """

    collision: CollisionModel
    source: CheckGeometry
    others: tuple[PlacedShape, ...]
    others_at: tuple[OtherAt, ...]
    origin: pin.SE3
    resolution: EdgeResolution
    start: tuple[float, ...]
    goals: tuple[tuple[float, ...], ...]
    path: np.ndarray | None = None
    target_only: bool = False
    plan: str = "never"
    timeout_s: float = 1.0
    seed: int | None = None
    cancel: Cancel | None = None
    spent: tuple[float, int] = (0.0, 0)


@dataclass(frozen=True)
class CheckedMove:
    """The path a checked move may take.

    Attributes:
        waypoints: Its corners, start and goal included, one row each [rad or m].
        planned: The planner's answer when it was planned (None: straight, or given).
        allowed: Pairs in contact at the start that the move may leave.
        revision: The workcell's revision it was checked against.
    """

    waypoints: np.ndarray
    planned: PlannedPath | None
    allowed: frozenset[Pair]
    revision: int

    @property
    def goal(self) -> tuple[float, ...]:
        """Where the move ends [rad or m]."""
        return tuple(float(x) for x in self.waypoints[-1])


class MoveChecker:
    """Checks and plans moves on one thread, keeping a checker per robot."""

    def __init__(self) -> None:
        self._cache: dict[int, tuple[Hashable, ValidityChecker]] = {}

    def checker(self, request: MoveRequest) -> ValidityChecker:
        """The robot's checker for what ``request`` is checked against (built if needed)."""
        placed = tuple((name, where.homogeneous.tobytes()) for name, _, where in request.others)
        key = (
            request.source.revision,
            placed,
            request.origin.homogeneous.tobytes(),
            request.resolution,
        )
        cached = self._cache.get(id(request.collision))
        if cached is not None and cached[0] == key and cached[1].collision is request.collision:
            return cached[1]
        checker = ValidityChecker(
            request.collision,
            request.others,
            origin=request.origin,
            resolution=request.resolution,
            source=request.source,
        )
        self._cache[id(request.collision)] = (key, checker)
        return checker

    def check(self, request: MoveRequest) -> CheckedMove:
        """The path ``request``'s move may take (see the module).

        Raises:
            PathCollides: the goal or the path collides (naming the pair and where).
            NoWayAround: blocked, and no plan around it (``plan="blocked"``).
            PlanningError: ``plan="always"`` found no path (an end collides, none in time).
            PlanCancelled: ``request.cancel`` was set before a plan was found.
        """
        checker = self.checker(request)
        start = np.asarray(request.start, dtype=float)
        allowed = (
            frozenset() if checker.is_valid(start) else frozenset(checker.batch.colliding(start))
        )
        revision = request.source.revision
        if request.plan == "always":
            return self._planned(checker, request, allowed)
        goal = np.asarray(request.goals[0], dtype=float)
        if request.target_only:
            blocked = first_blocked(checker, goal[None, :], allowed)
            if blocked is not None:
                raise PathCollides(*blocked[1], 1.0, True, target=goal.tolist())
            return CheckedMove(np.array([start, goal]), None, allowed, revision)
        tries = (
            [request.path]
            if request.path is not None
            else [np.array([start, np.asarray(g, dtype=float)]) for g in request.goals]
        )
        collides: PathCollides | None = None
        for waypoints in tries:  # the first free way (the goals in order); else the first's hit
            points = path_points(checker, waypoints)
            blocked = first_blocked(checker, points, allowed)
            if blocked is None:
                return CheckedMove(np.asarray(waypoints, dtype=float), None, allowed, revision)
            if collides is None:
                index, pair = blocked
                collides = PathCollides(
                    *pair,
                    index / max(len(points) - 1, 1),
                    False,
                    target=np.asarray(waypoints[-1]).tolist(),
                )
        assert collides is not None
        if request.plan != "blocked" or request.path is not None:
            raise collides
        try:
            return self._planned(checker, request, allowed)
        except PlanningError as exc:
            raise NoWayAround(str(collides), str(exc)) from exc

    def _planned(
        self, checker: ValidityChecker, request: MoveRequest, allowed: frozenset[Pair]
    ) -> CheckedMove:
        """A plan to the first of ``request.goals`` that plans within the time limit."""
        began = time.perf_counter() - request.spent[0]
        states, searched = request.spent[1], request.spent[1] > 0
        collided: GoalCollides | None = None
        for goal in request.goals:
            if request.cancel is not None:
                request.cancel.check()
            left = request.timeout_s - (time.perf_counter() - began)
            if left <= 0:
                break
            try:
                path = plan_for(
                    checker,
                    request.start,
                    goal,
                    timeout_s=max(left, 1e-3),
                    seed=request.seed,
                    cancel=request.cancel,
                )
            except GoalCollides as exc:
                collided = collided or exc
                continue
            except NoPathFound as exc:
                states, searched = states + exc.states, True
                continue
            return CheckedMove(path.waypoints, path, allowed, request.source.revision)
        if collided is not None and not searched:
            raise collided
        raise NoPathFound(request.timeout_s, states)


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


DISTINCT_RAD = 1e-3  # [rad or m] answers closer than this on every joint are one answer


def goal_candidates(
    solver: IkSolver,
    target: Target,
    near: Sequence[float],
    tool: pin.SE3 | None = None,
    count: int = 6,
) -> list[tuple[float, ...]]:
    """Up to ``count`` distinct chain values [rad or m] that put the tool at ``target``.

    Args:
        solver: The robot's IK solver.
        target: Tool pose in the base frame, or a point (``ik.PointTarget``).
        near: The arm's chain values now [rad or m].
        tool: Tool offset from the end-effector link.
        count: Most answers returned.

    Raises:
        Unreachable: the solver's own answer fails (beyond reach, or no attempt got there).
    """
    first = solver.solve(target, near, tool)
    found = [np.array(first)]
    settings = solver.settings
    solver.chain.set_tool(tool)
    goal = goal_in_world(target, solver.chain.base_placement)
    for start in solver.seeds.ranked(goal, settings.max_attempts):
        if len(found) >= count:
            break
        descent = solver.newton.descend(start, goal, settings.max_iterations)
        if not descent.ok:
            continue
        q = np.array(solver.chain.to_chain(descent.q, near))
        if all(np.max(np.abs(q - other)) > DISTINCT_RAD for other in found):
            found.append(q)
    rest = sorted(found[1:], key=lambda q: float(np.linalg.norm(q - np.asarray(near))))
    return [tuple(float(x) for x in q) for q in (found[0], *rest)]
