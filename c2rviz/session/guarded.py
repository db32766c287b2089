"""Guarded moves and planned paths: checked off the event loop, played on the checked path.

With ``guard on`` (or ``plan``) a joint-space move goes like this:

1. If the arm is moving, it brakes first, along the path it was checked on, at the
   joints' full limits (``Travels.stop``; the move it was on hears "preempted"):
   a guarded arm never blends into a new move off its checked paths.
2. A snapshot of what the move is checked against is taken on the loop
   (``planning.MoveRequest``: the robot's checks, the other robots where they
   stand, the start: where the arm comes to rest) and checked off the loop
   (``planning.MoveChecker``): the goal alone for a move shown at once, else the
   straight joint-space path, on the worker's work lane; a plan (``guard plan``:
   planned around when the straight path is blocked; ``plan``: always planned, the
   direct edge first) searches on its plan lane, in a process of its own, where
   ``stop``, the client closing or a newer move of the session cancel it
   (``planning.errors``; ``plan_process``).
3. Back on the loop the world may have changed meanwhile: the workcell must be the
   one checked (its revision), and every other robot that stood still stand where
   it stood; else the move is checked again, up to ``TRIES`` times, and then
   refused (``WorldChanged``). If another command sent the arm elsewhere meanwhile,
   this one is refused (``ArmMoved``): the newer command wins.
4. The move is played as a ``TimedPath`` on the checked polyline (a straight move
   is a one-edge path) at the session's speed, and ``GuardWatch`` keeps
   re-checking it while it runs (a new object, another robot's move).
"""

from __future__ import annotations

import asyncio
import functools
import inspect
from collections.abc import Awaitable, Sequence
from typing import Protocol, TypeVar

import numpy as np

from ..collision.model import NoFreeConfiguration
from ..errors import ArmMoved, C2rvizError, PathCollides
from ..planning import (
    CheckedMove,
    EdgeResolution,
    MoveChecker,
    MoveRequest,
    TimedPath,
    time_path,
)
from ..planning.errors import Cancel
from ..protocol import replies
from ..world.moves import Travel
from ..world.state import RobotState
from ..world.world import World
from .guard_watch import world_request
from .plan_process import plan_job
from .services import Services
from .worker import Worker

T = TypeVar("T")
TRIES = 3  # checks of one move while the world keeps changing under it
DRAWS = 1000  # random configurations a guarded rand draws at most
RAND_GOALS = 8
"""Free configurations a guarded ``rand`` offers when the path is checked (motion on or
follow): the first one the arm reaches along a free path is taken."""
_TAKEN = "another command moved the arm while this move was checked; nothing moved, send it again"


class GuardedSession(Protocol):
    """What a guarded move needs of the session that sends it (``session.Session``)."""

    services: Services
    world: World
    state: RobotState
    travel: Travel
    source: str
    motion: str
    speed: float
    plan_around: bool
    plan_timeout_s: float
    plan_seed: int | None
    last_plan: np.ndarray | None

    @property
    def resolution(self) -> EdgeResolution: ...

    def now(self) -> tuple[float, ...]: ...


class WorldChanged(C2rvizError):
    """The world changed under a move each time it was checked: nothing moved."""

    def __init__(self, tries: int) -> None:
        self.tries = tries
        super().__init__(
            f"the world changed while the move was checked ({tries} times: objects or "
            "robots moved); nothing moved, send it again"
        )


def checker_of(worker: Worker) -> MoveChecker:
    """The worker's move checker (kept in its cache, used on its work lane's thread)."""
    checker = worker.cache.get("moves")
    if not isinstance(checker, MoveChecker):
        checker = worker.cache["moves"] = MoveChecker()
    return checker


def request(
    session: GuardedSession,
    start: Sequence[float],
    goals: Sequence[Sequence[float]],
    *,
    path: np.ndarray | None = None,
    target_only: bool = False,
    plan: str = "never",
    cancel: Cancel | None = None,
) -> MoveRequest:
    """What a move of ``session``'s robot is checked against now, with its settings."""
    return world_request(
        session.world,
        session.state.name,
        session.resolution,
        start,
        goals,
        path=path,
        target_only=target_only,
        plan=plan,
        timeout_s=session.plan_timeout_s,
        seed=session.plan_seed,
        cancel=cancel,
    )


def unchanged(session: GuardedSession, asked: MoveRequest, at_rest: bool) -> bool:
    """True when ``asked`` still describes the world: same workcell, the other robots that
    stood still where they stood, and (``at_rest``) the arm at rest at its start."""
    world, state = session.world, session.state
    if asked.collision.revision != asked.source.revision:
        return False
    if at_rest and (session.travel.active or tuple(state.q) != asked.start):
        return False
    for name, q, _ in asked.others_at:
        if q is not None and (world.moving(name) or tuple(world.robots[name].q) != q):
            return False
    return True


async def checked_move(
    session: GuardedSession,
    goals: Sequence[Sequence[float]],
    *,
    plan: str = "never",
    path_from: np.ndarray | None = None,
) -> tuple[CheckedMove, bool]:
    """Check (or plan) a move of ``session``'s robot to the first workable of ``goals``, off
    the loop, from where the arm comes to rest; return it and whether it is shown at once.

    Args:
        session: Whose robot moves.
        goals: Where it may end, in order of preference [rad or m].
        plan: ``never``, ``blocked`` or ``always`` (``planning.MoveChecker``).
        path_from: A polyline to check instead (rows, from the arm at rest).

    Raises:
        PathCollides, PlanningError: refused (nothing moved).
        FaultStop, MotionInterrupted: a stop holds the arm, or came while it was checked.
        PlanCancelled: its plan was cancelled (nothing moved).
        WorldChanged: the world changed under each of ``TRIES`` checks.
    """
    at_once = session.motion == "off" and plan != "always" and path_from is None
    for _ in range(TRIES):
        if not at_once and session.travel.active:  # brake on the checked path first
            session.world.travels.stop(
                session.state, session.source, f"preempted by {session.source}"
            )
        start = tuple(session.state.target if session.travel.active else session.state.q)
        if at_once:
            start = session.now()
        check = _check(session, start, goals, path_from, at_once, plan)
        asked, checked = await unstopped(session, check)
        if not at_once:
            if session.travel.active and not session.travel.stopping:
                raise ArmMoved(_TAKEN)  # not our brake: another command took the arm
            rest = session.world.travels.rest(session.state)
            if rest is not None:
                await rest
            if tuple(session.state.q) != asked.start:
                raise ArmMoved(_TAKEN)
        if unchanged(session, asked, at_rest=not at_once):
            return checked, at_once
    raise WorldChanged(TRIES)


async def unstopped(session: GuardedSession, work: Awaitable[T]) -> T:
    """``work`` done off the loop for a move of ``session``'s robot (its IK, line or
    check): refused at once while a stop holds the robot, and when it ends if a stop came
    meanwhile, lifted or not (a move asked before a stop never plays after its ``reset``).

    Raises:
        FaultStop: a stop holds the robot (``work`` is closed unawaited).
        MotionInterrupted: a stop came while ``work`` ran.
    """
    faults, state = session.world.faults, session.state
    try:
        faults.refuse(state)
    except C2rvizError:
        if inspect.iscoroutine(work):
            work.close()
        raise
    stops = faults.of(state.name).stops
    result = await work
    faults.refuse(state, stops)
    return result


async def _check(
    session: GuardedSession,
    start: tuple[float, ...],
    goals: Sequence[Sequence[float]],
    path_from: np.ndarray | None,
    at_once: bool,
    plan: str,
) -> tuple[MoveRequest, CheckedMove]:
    """One check of a move, off the loop; what it was checked against, and the answer.

    The straight path (or the goal, or the path given) is checked on the worker's work
    lane; a plan (``plan="always"``, or ``"blocked"`` when the straight path is blocked)
    searches on its plan lane, where it can be cancelled.
    """
    worker, key = session.services.worker, ("move", id(session))
    if plan != "always":
        straight = "never" if plan == "blocked" else plan
        asked = request(session, start, goals, path=path_from, target_only=at_once, plan=straight)
        check = functools.partial(checker_of(worker).check, asked)
        try:
            return asked, await worker.run(check, key=key, owner=session)
        except PathCollides:
            if plan != "blocked" or at_once or path_from is not None:
                raise
    cancel = Cancel()
    asked = request(session, start, goals, path=path_from, plan=plan, cancel=cancel)
    job = functools.partial(plan_job, asked, worker.plan_processes)
    return asked, await worker.plan(job, key=key, owner=session, cancel=cancel)


def play_checked(
    session: GuardedSession, checked: CheckedMove, speed: float | None = None
) -> tuple[TimedPath, asyncio.Future[str] | None]:
    """Play ``checked`` from rest on the world's clock at ``speed`` % (default the
    session's; watched while it runs); the path played, and the reply on arrival (``motion
    on``) or None."""
    world, state = session.world, session.state
    limits = world.motion_limits(state.name)
    percent = session.speed if speed is None else speed
    play = time_path(checked.waypoints, limits, world.clock.now(), percent / 100.0)
    arrival = world.travels.play(state, play, session.source, wait=session.motion == "on")
    session.services.guards.watch(
        state.name, play, checked.allowed, session.source, session.resolution
    )
    return play, arrival


async def guarded_go(
    session: GuardedSession, goals: Sequence[Sequence[float]], speed: float
) -> str:
    """``Session.go`` under the guard (see the module) to the first workable of ``goals``:
    ``ok`` when shown, started (``follow``) or arrived (``on``); ``speed`` is the session's
    [%] when the move was asked (a door may change it for one move: it is read now, not
    once checked)."""
    plan = "blocked" if session.plan_around else "never"
    checked, at_once = await checked_move(session, goals, plan=plan)
    if session.plan_around:
        session.last_plan = checked.waypoints  # what `plan` shows: the path this move takes
    if at_once:
        session.world.set_q(checked.goal, session.state.name, session.source)
        return replies.OK
    _, arrival = play_checked(session, checked, speed)
    return replies.OK if arrival is None else await arrival


async def guarded_rand(session: GuardedSession) -> str:
    """``rand`` under the guard: a configuration free of everything, drawn off the loop
    (with the path checked, ``RAND_GOALS`` of them: the first with a free path is taken)."""
    rng, worker, speed = session.services.rng, session.services.worker, session.speed
    checker = checker_of(worker)
    asked = request(session, session.now(), [session.now()], target_only=True)
    name = session.state.robot.name
    wanted = 1 if session.motion == "off" else RAND_GOALS

    def draw() -> list[list[float]]:
        batch = checker.checker(asked).batch
        found: list[list[float]] = []
        while len(found) < wanted and (q := batch.random_free(rng, DRAWS)) is not None:
            found.append(q)
        if not found:
            raise NoFreeConfiguration(name, DRAWS, batch.lasting(rng))
        return found

    goals = await worker.run(draw, key=("move", id(session)), owner=session)
    return await guarded_go(session, goals, speed)
