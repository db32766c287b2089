"""Running guarded moves, re-checked when the world changes under them: ``GuardWatch``.

A guarded move was checked against the world as it was when it started. When a
workcell object is set or removed, or another robot of the cell starts a move,
stops, or is put somewhere at once, every guarded move still running is checked
again, on the worker's thread before any other work: the rest of its path (its
played motion sampled every ``DT`` from now to its arrival, each interval at the
checker's resolution) against the workcell now and the robots that stand still,
and, time step by time step, against the robots that move (each where its own
motion puts it then). Contacts the move started in, or is in now, may be left
(``planning.first_blocked``). If something is in the way, the arm brakes on its
path at once, at the joints' full limits, and the client waiting for the move
hears ``stopped: link_e would hit wall (the workcell changed)``.

The arm keeps moving while the check runs (milliseconds), so it stops before the
contact when the contact is at least that and the braking distance ahead.

What a move is checked against, taken on the event loop, is ``world_request`` (at the
start of this module; a guarded move's first check takes it too): a
``planning.MoveRequest`` holds a robot's collision checks as they are now, the other
robots' shapes where they are now (``still_only``: only those standing still, when the
moving ones are checked in time), and the move's start, goals and settings; the
worker's thread checks it while the loop goes on.
"""

from __future__ import annotations

import asyncio
import copy
import functools
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..collision.batch import PlacedShape
from ..collision.model import CollisionModel, Pair
from ..collision.other_robots import first_hit_between, placed_shapes
from ..motion.path_play import PathPlay
from ..planning import EdgeResolution, MoveChecker, MoveRequest, first_blocked
from ..planning.errors import Cancel
from ..planning.guarded_move import OtherAt
from ..world.clock import Hold
from ..world.observer import Observer
from ..world.world import World
from .lanes import Superseded, WorkerBusy
from .worker import Worker


def world_request(
    world: World,
    robot: str,
    resolution: EdgeResolution,
    start: Sequence[float],
    goals: Sequence[Sequence[float]],
    *,
    path: np.ndarray | None = None,
    target_only: bool = False,
    plan: str = "never",
    timeout_s: float = 1.0,
    seed: int | None = None,
    still_only: bool = False,
    cancel: Cancel | None = None,
) -> MoveRequest:
    """What a move of ``robot`` is checked against now (on the loop): its checks, and the
    other robots where they are (``still_only``: only those standing still); ``cancel``
    stops its plan, if it plans."""
    state = world.state(robot)
    model = world.collision_model(robot)
    shapes: list[PlacedShape] = []
    key: list[OtherAt] = []
    for name, other in world.robots.items():
        moving = world.moving(name)
        if name == robot or (moving and still_only):
            continue
        q = tuple(world.now(name))
        shapes += placed_shapes(name, world.collision_model(name), q, other.origin)
        key.append((name, None if moving else q, other.origin.homogeneous.tobytes()))
    return MoveRequest(
        model,
        model.check_geometry(),
        tuple(shapes),
        tuple(key),
        state.origin,
        resolution,
        tuple(float(x) for x in start),
        tuple(tuple(float(x) for x in goal) for goal in goals),
        path,
        target_only,
        plan,
        timeout_s,
        seed,
        cancel,
    )


log = logging.getLogger("c2rviz")

DT = 0.01  # [s] of the world's clock between two samples of a running move re-checked

Hit = tuple[float, Pair]


@dataclass(eq=False)
class Run:
    """A guarded move running: what it plays, the contacts it may leave, who moves it."""

    play: PathPlay
    allowed: frozenset[Pair]
    mover: str
    resolution: EdgeResolution


@dataclass(frozen=True, eq=False)
class _Recheck:
    """What a running move is re-checked against, taken on the loop."""

    t0: float
    play: PathPlay
    request: MoveRequest
    allowed: frozenset[Pair]
    model: CollisionModel
    origin: pin.SE3
    moving: tuple[tuple[str, CollisionModel, pin.SE3, Callable[[float], Sequence[float]]], ...]


class GuardWatch(Observer):
    """The guarded moves running, by robot, and their re-checks (see the module)."""

    def __init__(
        self,
        world: World,
        worker: Worker,
        request: Callable[[str, EdgeResolution, Sequence[float]], MoveRequest],
    ) -> None:
        """Watch ``world``'s robots.

        Args:
            world: The world.
            worker: Where the re-checks run.
            request: ``request(robot, resolution, start)``: what a move of ``robot`` is
                checked against now, with the other robots that stand still (the
                moving ones are checked in time here).
        """
        self.world = world
        self.worker = worker
        self.request = request
        self.runs: dict[str, Run] = {}
        self._rechecking: dict[str, str | None] = {}  # robot -> the cause of one more, if any
        self.stops = 0
        """Running moves stopped because the world changed under them."""

    def watch(
        self,
        robot: str,
        play: PathPlay,
        allowed: frozenset[Pair],
        mover: str,
        resolution: EdgeResolution,
    ) -> None:
        """``robot`` now plays ``play``, a guarded move of ``mover`` (checked at
        ``resolution``) that may leave ``allowed``; re-check it at once if another
        robot moves."""
        self.runs[robot] = Run(play, allowed, mover, resolution)
        moving = [name for name in self.world.robots if name != robot and self.world.moving(name)]
        if moving:
            self.recheck(robot, f"{moving[0]} moves")

    def current(self, robot: str) -> Run | None:
        """The guarded move ``robot`` is running now, if any."""
        run = self.runs.get(robot)
        if run is None:
            return None
        travel = self.world.travel(robot)
        if not travel.active or travel.path is not run.play:
            del self.runs[robot]
            return None
        return run

    # The world's effects.

    def on_objects(self, robot: str, objects: Sequence[object]) -> None:
        self.recheck(robot, "the workcell changed")

    def on_motion(self, robot: str, t: float) -> None:
        for other in list(self.runs):
            if other != robot:
                self.recheck(other, f"{robot} moved")

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        if len(self.runs) > (robot in self.runs) and not self.world.moving(robot):
            self.on_motion(robot, t)  # put somewhere at once (or arrived)

    # The re-check.

    def recheck(self, robot: str, cause: str, urgent: bool = True) -> None:
        """Check ``robot``'s running guarded move again, first on the worker (``urgent``).

        While one re-check of the robot runs, more changes make one more after it, not
        urgent: a robot streamed to new places at once cannot keep the worker from the
        other clients' work.
        """
        run = self.current(robot)
        if run is None:
            return
        if robot in self._rechecking:
            self._rechecking[robot] = cause  # once more when this one is done
            return
        world = self.world
        state = world.state(robot)
        t0 = world.clock.now()
        moving = tuple(
            (name, world.collision_model(name), other.origin, _sampler(world, name))
            for name, other in world.robots.items()
            if name != robot and world.moving(name)
        )
        snapshot = _Recheck(
            t0,
            copy.copy(run.play),  # the loop may brake the original meanwhile
            self.request(robot, run.resolution, run.play.sample(t0)),
            run.allowed,
            world.collision_model(robot),
            state.origin,
            moving,
        )
        checker = self._checker()
        self._rechecking[robot] = None
        # a virtual clock stands still until the re-check answers (else nobody holds it: it
        # would jump to the move's end while the check runs, through what it finds)
        hold = world.clock.hold()
        try:
            done = self.worker.run(
                functools.partial(_first_hit, checker, snapshot),
                key=("watch", robot),
                urgent=urgent,
            )
        except WorkerBusy:  # (only a follow-up, not urgent, can be refused)
            done = asyncio.get_running_loop().create_future()
            done.set_result(None)
        done.add_done_callback(functools.partial(self._checked, robot, run, cause))
        done.add_done_callback(functools.partial(_let_go, hold))

    def _checker(self) -> MoveChecker:
        checker = self.worker.cache.get("moves")
        if not isinstance(checker, MoveChecker):
            checker = self.worker.cache["moves"] = MoveChecker()
        return checker

    def _checked(self, robot: str, run: Run, cause: str, done: asyncio.Future[Hit | None]) -> None:
        again = self._rechecking.pop(robot, None)
        if done.cancelled():
            return  # the program stops
        if again is not None:
            self.recheck(robot, again, urgent=False)
        error = done.exception()
        if error is not None:
            if not isinstance(error, Superseded):  # (a newer re-check replaced it)
                log.warning("re-checking %s's running guarded move failed: %r", robot, error)
            return
        hit: Hit | None = done.result()
        if hit is None or self.current(robot) is not run:
            return
        _, (first, second) = hit
        self.stops += 1
        self.world.travels.stop(
            self.world.state(robot), "guard", f"stopped: {first} would hit {second} ({cause})"
        )


def _sampler(world: World, name: str) -> Callable[[float], Sequence[float]]:
    """A copy of robot ``name``'s motion now, sampled at a time [s] (for another thread)."""
    travel = world.travel(name)
    if travel.path is not None:
        return copy.copy(travel.path).sample
    motion = copy.copy(travel.motion)
    return lambda t: motion.sample(t)[0]


def _first_hit(checker: MoveChecker, snap: _Recheck) -> Hit | None:
    """When (clock time [s]) and how the rest of a running move first meets something."""
    arrival = snap.play.arrival
    times = np.append(np.arange(snap.t0, arrival, DT), max(arrival, snap.t0))
    qs = np.array([snap.play.sample(float(t)) for t in times])
    valid = checker.checker(snap.request)
    parts, owners = [qs[:1]], [0]
    for k in range(len(qs) - 1):
        points = valid.edge_points(qs[k], qs[k + 1])[1:]
        parts.append(points)
        owners += [k] * len(points)  # a hit there: from the interval's start on
    allowed = snap.allowed | frozenset(valid.batch.colliding(qs[0]))
    blocked = first_blocked(valid, np.vstack(parts), allowed)
    hit: Hit | None = None
    if blocked is not None:
        hit = (float(times[owners[blocked[0]]]), blocked[1])
    if snap.moving:
        for k, t in enumerate(times):
            if hit is not None and t >= hit[0]:
                break
            others = [
                (name, model, sample(float(t)), origin)
                for name, model, origin, sample in snap.moving
            ]
            found = first_hit_between(snap.model, snap.origin, others, [qs[k]])
            if found is not None:
                hit = (float(t), found[1])
                break
    return hit


def _let_go(hold: Hold, done: asyncio.Future[Any]) -> None:
    """A re-check answered (its ``_checked`` ran first): time may run on."""
    hold.close()
