"""A fast, batched collision check of one robot, for one thread: ``BatchCheck``.

A ``CollisionModel`` hands out what it checks (``CheckGeometry``: the robot's
shapes, the workcell's objects, the pairs and their names); a ``BatchCheck`` is
a private snapshot of that, with the other robots of a cell added as fixed
obstacles (each checked against every link the chain moves), and may leave
pairs out (``without``) or keep only some (``only``). Checks go to Pinocchio in
batches (``computeCollisionsInParallel`` on one thread, with a broad phase: a
dynamic AABB tree skips the pairs far apart, about twice as fast as every
pair's narrow phase), stopping at the first hit.

Batches are cut into chunks of ``CHUNK`` configurations: Pinocchio holds the
interpreter's lock through each call, so a chunk is the longest the event loop
may wait for a worker thread that checks (under a millisecond with 100
objects). Build a new check when the workcell or another robot changes (about a
millisecond); the model's ``revision`` says when.
"""

from __future__ import annotations

import warnings
from collections.abc import Collection, Sequence
from dataclasses import dataclass
from typing import Any, cast

import coal
import numpy as np
import pinocchio as pin

from ..robot.model import Robot
from .geometry import Pair

CHUNK = 8  # configurations per Pinocchio call (the event loop's longest wait, see the module)

PlacedShape = tuple[str, Any, pin.SE3]
"""A name, a coal geometry and its placement in the cell's (world) frame [m]."""

_Pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager


@dataclass(frozen=True)
class CheckGeometry:
    """What a ``CollisionModel`` checks, to be copied by a checker of one's own.

    Attributes:
        geometry: The robot's shapes and the workcell's objects, with the pairs
            checked as collision pairs (shared: copy it, never change it).
        requests: Geometry data whose collision requests say how exact checks are.
        names: The pair of each collision pair, in order: ``(link, link)`` or
            ``(link, object)``.
        moving: Geometry indices of the shapes the chain moves.
        link_of: The link of each robot shape, by geometry index.
        revision: Counts the model's changes (a new object, one removed).
    """

    geometry: pin.GeometryModel
    requests: pin.GeometryData
    names: tuple[Pair, ...]
    moving: tuple[int, ...]
    link_of: tuple[str, ...]
    revision: int
    touch: frozenset[str] = frozenset()
    """Links that may touch parts (the fingers): never checked against another robot's
    held part (``checks.held_as_links``)."""
    parts: frozenset[str] = frozenset()
    """Every part's name."""
    other_touch: frozenset[str] = frozenset()
    """The other robots' links that may touch parts (``robot/link``)."""


def may_touch(source: CheckGeometry, mine: str, other: str) -> bool:
    """Whether this robot's shape ``mine`` and another robot's ``other`` (``robot/link``)
    are a finger and a held part, which may touch."""
    return (mine in source.touch and other.rsplit("/", 1)[-1] in source.parts) or (
        mine in source.parts and other in source.other_touch
    )


class BatchCheck:
    """Whether configurations of one robot collide: itself, its workcell, other robots.

    Use from one thread (it holds its own Pinocchio data).

    Attributes:
        robot: The robot.
        names: The pair of each collision pair checked, in order.
        checks: Configurations checked so far (every point of every batch looked at).
    """

    def __init__(
        self,
        robot: Robot,
        source: CheckGeometry,
        others: Sequence[PlacedShape] = (),
        *,
        origin: pin.SE3 | None = None,
        without: Collection[Pair] = (),
        only: Collection[Pair] | None = None,
    ) -> None:
        """Copy ``source``'s checks, add the other robots' shapes, filter the pairs.

        Args:
            robot: The robot checked.
            source: Its model's checks (``CollisionModel.check_geometry``).
            others: Shapes of the other robots of the cell, placed in the cell; each
                is checked against every moving link, as ``(link, name)``.
            origin: Placement of this robot's model root frame in the cell
                (identity if None) [m].
            without: Pairs left out.
            only: If given, the only pairs checked (after ``without``).
        """
        self.robot = robot
        self.checks = 0
        geometry = pin.GeometryModel(source.geometry)
        pairs = list(zip(geometry.collisionPairs, source.names))
        to_root = (origin if origin is not None else pin.SE3.Identity()).inverse()
        for name, shape, placement in others:
            k = geometry.addGeometryObject(
                pin.GeometryObject(f"cell/{name}", 0, 0, to_root * placement, shape)
            )
            pairs += [
                (pin.CollisionPair(i, k), (source.link_of[i], name))
                for i in source.moving
                if not may_touch(source, source.link_of[i], name)
            ]
        excluded = set(without)
        kept = [(p, n) for p, n in pairs if n not in excluded and (only is None or n in only)]
        if len(kept) != len(geometry.collisionPairs):
            geometry.removeAllCollisionPairs()
            for pair, _ in kept:
                geometry.addCollisionPair(pair)
        self.names: list[Pair] = [name for _, name in kept]
        for obj in geometry.geometryObjects:  # the broad phase needs their bounding boxes
            if obj.geometry.aabb_radius <= 0:
                obj.geometry.computeLocalAABB()
        self._geometry = geometry
        self._data = geometry.createData()
        copy_requests(source.requests, self._data)
        self._pool = _Pool(robot.model, geometry, 1)
        copy_requests(source.requests, self._pool.getGeometryData(0))  # it holds a reference
        self._manager = self._pool.getBroadPhaseManager(0)  # one state: no batch to build
        self._model = robot.model
        self._model_data = robot.model.createData()
        self._neutral = np.asarray(robot.neutral, dtype=float)
        joints = robot.joints
        self._plain = np.array([i for i, joint in enumerate(joints) if joint.nq == 1], dtype=int)
        self._plain_q = np.array([joints[i].idx_q for i in self._plain], dtype=int)
        self._turning = [(i, joint.idx_q) for i, joint in enumerate(joints) if joint.nq == 2]

    def configurations(self, qs: np.ndarray | Sequence[Sequence[float]]) -> np.ndarray:
        """Pinocchio configurations (``nq`` x k) of chain values ``qs`` (k x n) [rad or m]."""
        qs = np.atleast_2d(np.asarray(qs, dtype=float))
        if len(qs) == 1:  # the common case of a single check: the robot's own, quicker
            return self.robot.configuration(cast(Sequence[float], qs[0]))[:, None]
        full = np.repeat(self._neutral[:, None], len(qs), axis=1)
        full[self._plain_q] = qs[:, self._plain].T
        for i, idx in self._turning:
            full[idx] = np.cos(qs[:, i])
            full[idx + 1] = np.sin(qs[:, i])
        return full

    def first_invalid(self, qs: np.ndarray | Sequence[Sequence[float]]) -> int | None:
        """Index of the first row of ``qs`` (k x n) [rad or m] in collision, or None.

        The rows are checked in order, a chunk at a time, stopping at the first hit.
        """
        if len(qs) == 0:
            return None
        if not self.names:
            self.checks += len(qs)
            return None
        configs = self.configurations(qs)
        for start in range(0, configs.shape[1], CHUNK):
            chunk = np.asfortranarray(configs[:, start : start + CHUNK])
            hits = pin.computeCollisionsInParallel(1, self._pool, chunk, True, True)
            if np.any(hits):
                first = int(np.argmax(hits))
                self.checks += first + 1
                return start + first
            self.checks += chunk.shape[1]
        return None

    def hits(self, qs: np.ndarray | Sequence[Sequence[float]]) -> np.ndarray:
        """Whether each row of ``qs`` (k x n) [rad or m] is in collision (k bools)."""
        out = np.zeros(len(qs), dtype=bool)
        if len(qs) == 0 or not self.names:
            self.checks += len(qs)
            return out
        configs = self.configurations(qs)
        for start in range(0, configs.shape[1], CHUNK):
            chunk = np.asfortranarray(configs[:, start : start + CHUNK])
            out[start : start + CHUNK] = pin.computeCollisionsInParallel(
                1, self._pool, chunk, True, False
            )
        self.checks += len(qs)
        return out

    def is_valid(self, q: Sequence[float] | np.ndarray) -> bool:
        """True when ``q`` [rad or m] collides with nothing checked."""
        self.checks += 1
        if not self.names:
            return True
        config = self.robot.configuration(cast(Sequence[float], q))  # an array does as well
        return not pin.computeCollisions(self._model, self._model_data, self._manager, config, True)

    def colliding(self, q: Sequence[float] | np.ndarray) -> list[Pair]:
        """Every checked pair in collision at ``q`` [rad or m], sorted."""
        if not self.names:
            return []
        config = self.configurations(np.asarray(q, dtype=float)[None, :])[:, 0]
        data = self._data
        if not pin.computeCollisions(
            self._model, self._model_data, self._geometry, data, config, False
        ):
            return []
        results = data.collisionResults
        return sorted({self.names[k] for k, r in enumerate(results) if r.isCollision()})

    def describe(self, q: Sequence[float] | np.ndarray) -> Pair | None:
        """The first (sorted) colliding pair at ``q`` [rad or m]: ``(link, link)``,
        ``(link, object)`` or ``(link, robot/link)``; None when ``q`` is free."""
        pairs = self.colliding(q)
        return pairs[0] if pairs else None

    def random_free(self, rng: np.random.Generator, tries: int = 1000) -> list[float] | None:
        """A random configuration within the limits that collides with nothing, or None
        after ``tries`` draws (drawn a chunk at a time)."""
        robot = self.robot
        drawn = 0
        while drawn < tries:
            count = min(CHUNK, tries - drawn)
            qs = np.array([robot.random(rng) for _ in range(count)])
            drawn += count
            hits = self.hits(qs)
            if not np.all(hits):
                return [float(x) for x in qs[int(np.argmin(hits))]]
        return None

    def lasting(self, rng: np.random.Generator, looks: int = 50) -> list[Pair]:
        """The pairs colliding in each of ``looks`` random configurations: contacts no
        joint can undo (an object through the robot's base), sorted."""
        always: set[Pair] | None = None
        for _ in range(looks):
            pairs = set(self.colliding(self.robot.random(rng)))
            always = pairs if always is None else always & pairs
            if not always:
                break
        return sorted(always or ())


def copy_requests(source: pin.GeometryData, target: pin.GeometryData) -> None:
    """Make ``target``'s requests answer as ``source``'s: exact as they are, and free of
    history (``geometry.configure_requests``: coal's warm start made an answer depend
    on the configuration checked before)."""
    exact = all(request.enable_contact for request in source.collisionRequests)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the warm start's old switch
        for request in target.collisionRequests:
            request.enable_contact = exact
            request.enable_cached_gjk_guess = False
            request.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
