"""Which configurations and edges a planner may use: a fast, batched collision check.

``ValidityChecker`` answers for one robot against itself and its workcell (the
pairs its ``CollisionModel`` chose, with the same exact requests) and against
the other robots of a cell, held where they stand while it plans. Checks go to
Pinocchio in batches (``computeCollisionsInParallel`` on one thread, with a
broad phase: a dynamic AABB tree skips the pairs far apart, about twice as
fast as every pair's narrow phase), stopping at the first hit. An edge is
checked as ``edge_resolution.py`` says: its joint grid, far end first and then
coarse to fine, and then, if the tool travels more than its step between grid
points, the points cutting those intervals.

The checker is a snapshot: build a new one when the workcell or another robot
changes (about a millisecond).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any, cast

import coal
import numpy as np
import pinocchio as pin

from c2rviz.collision import CollisionModel

from .edge_resolution import TOOL_MARGIN, EdgeResolution, Joints, coarse_first, edge_resolution

__all__ = ["PlacedShape", "ValidityChecker", "robot_shapes"]

PlacedShape = tuple[str, Any, pin.SE3]
"""A name, a coal geometry and its placement in the cell's (world) frame [m]."""

_Pool = pin.BroadPhaseManagerPool_DynamicAABBTreeCollisionManager


def robot_shapes(
    name: str, collision: CollisionModel, q: Sequence[float], origin: pin.SE3
) -> list[PlacedShape]:
    """Every collision shape of the robot ``name`` at ``q`` [rad or m], placed in the cell.

    Args:
        name: The robot's name in the cell; each shape is named ``name/link``.
        collision: Its collision model.
        q: Its chain values [rad or m].
        origin: Placement of its model's root frame in the cell [m].
    """
    return [
        (f"{name}/{link}", geometry, origin * placement)
        for link, geometry, placement in collision.link_shapes(q)
    ]


class ValidityChecker:
    """Whether configurations and edges of one robot are free of collisions (one thread).

    Attributes:
        collision: The robot's collision model (self pairs and workcell objects).
        robot: Its robot.
        resolution: How finely edges are checked.
        checks: Configurations checked so far (every point of every batch looked at).
    """

    def __init__(
        self,
        collision: CollisionModel,
        others: Sequence[PlacedShape] = (),
        *,
        origin: pin.SE3 | None = None,
        resolution: EdgeResolution | None = None,
    ) -> None:
        """Snapshot ``collision``'s checks and add the other robots' shapes as fixed obstacles.

        Args:
            collision: The planning robot's collision model.
            others: Shapes of the other robots of the cell, placed in the cell
                (``robot_shapes``); each is checked against every moving link.
            origin: Placement of this robot's model root frame in the cell
                (identity if None) [m].
            resolution: Edge resolution (``edge_resolution(robot)`` if None).
        """
        robot = collision.robot
        self.collision = collision
        self.robot = robot
        self.resolution = resolution if resolution is not None else edge_resolution(robot)
        self.checks = 0
        # CollisionModel keeps its checks private; reading them is the one coupling
        # (a CollisionModel method handing them out would end it).
        model_geometry, model_data, names = collision._checks
        geometry = pin.GeometryModel(model_geometry)
        self._names: list[tuple[str, str]] = list(names)
        to_root = (origin if origin is not None else pin.SE3.Identity()).inverse()
        for name, shape, placement in others:
            k = geometry.addGeometryObject(
                pin.GeometryObject(f"cell/{name}", 0, 0, to_root * placement, shape)
            )
            for i in collision._moving_geoms:
                geometry.addCollisionPair(pin.CollisionPair(i, k))
                self._names.append((collision._link_of[i], name))
        for obj in geometry.geometryObjects:  # the broad phase needs their bounding boxes
            if obj.geometry.aabb_radius <= 0:
                obj.geometry.computeLocalAABB()
        self._geometry = geometry
        self._data = geometry.createData()
        _copy_requests(model_data, self._data)
        self._pool = _Pool(robot.model, geometry, 1)
        _copy_requests(model_data, self._pool.getGeometryData(0))  # it holds a reference
        self._manager = self._pool.getBroadPhaseManager(0)  # one state: no batch to build
        self._model = robot.model
        self._model_data = robot.model.createData()
        self._neutral = np.asarray(robot.neutral, dtype=float)
        joints = robot.joints
        self._plain = np.array([i for i, joint in enumerate(joints) if joint.nq == 1], dtype=int)
        self._plain_q = np.array([joints[i].idx_q for i in self._plain], dtype=int)
        self._turning = [(i, joint.idx_q) for i, joint in enumerate(joints) if joint.nq == 2]

    def configurations(self, qs: np.ndarray | Sequence[Joints]) -> np.ndarray:
        """Pinocchio configurations (``nq`` x k) of chain values ``qs`` (k x n) [rad or m]."""
        qs = np.atleast_2d(np.asarray(qs, dtype=float))
        full = np.repeat(self._neutral[:, None], len(qs), axis=1)
        full[self._plain_q] = qs[:, self._plain].T
        for i, idx in self._turning:
            full[idx] = np.cos(qs[:, i])
            full[idx + 1] = np.sin(qs[:, i])
        return full

    def first_invalid(self, qs: np.ndarray | Sequence[Joints]) -> int | None:
        """Index of the first row of ``qs`` (k x n) [rad or m] in collision, or None.

        The rows are checked in order, in one call, stopping at the first hit.
        """
        if len(qs) == 0:
            return None
        hits = pin.computeCollisionsInParallel(1, self._pool, self.configurations(qs), True, True)
        first = int(np.argmax(hits)) if np.any(hits) else None
        self.checks += len(qs) if first is None else first + 1
        return first

    def is_valid(self, q: Joints) -> bool:
        """True when ``q`` [rad or m] collides with nothing checked."""
        self.checks += 1
        config = self.robot.configuration(cast(Sequence[float], q))  # an array does as well
        return not pin.computeCollisions(self._model, self._model_data, self._manager, config, True)

    def edge_points(self, q0: Joints, q1: Joints) -> np.ndarray:
        """Every point checked on the edge ``q0 -> q1``, ends included, in order ((k+1) x n)."""
        grid = self.resolution.grid(np.asarray(q0, dtype=float), np.asarray(q1, dtype=float))
        points, _ = self._refine(grid)
        return points

    def check_edge(self, q0: Joints, q1: Joints) -> tuple[bool, int]:
        """Whether the edge ``q0 -> q1`` is free (``q0`` is taken as checked), and the
        number of configurations that took."""
        before = self.checks
        grid = self.resolution.grid(q0, q1)
        rest = grid[1:]
        if self.first_invalid(rest[coarse_first(len(rest))]) is not None:
            return False, self.checks - before
        points, on_grid = self._refine(grid)
        extra = points[~on_grid]
        free = self.first_invalid(extra[coarse_first(len(extra))]) is None
        return free, self.checks - before

    def describe(self, q: Joints) -> tuple[str, str] | None:
        """The first (sorted) colliding pair at ``q`` [rad or m]: ``(link, link)``,
        ``(link, object)`` or ``(link, robot/link)``; None when ``q`` is free."""
        config = self.configurations(np.asarray(q, dtype=float)[None, :])[:, 0]
        data = self._data
        if not pin.computeCollisions(
            self._model, self._model_data, self._geometry, data, config, False
        ):
            return None
        return min(self._names[k] for k, r in enumerate(data.collisionResults) if r.isCollision())

    def bounds(self, start: Joints, goal: Joints) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Lower and upper bounds [rad or m] of the space to plan in: the joint limits,
        except that a continuous joint is searched within a turn beyond its start and goal."""
        lower, upper = list(self.robot.lower), list(self.robot.upper)
        for i, joint in enumerate(self.robot.joints):
            if joint.continuous:
                low, high = sorted((float(start[i]), float(goal[i])))
                lower[i] = max(lower[i], low - math.pi)
                upper[i] = min(upper[i], high + math.pi)
        return tuple(lower), tuple(upper)

    # --- the tool's travel --------------------------------------------------------

    def _refine(self, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``grid`` with its intervals cut where the tool travels more than its step,
        and which rows are grid points."""
        step = self.resolution.max_tool_step_m
        on_grid = np.ones(len(grid), dtype=bool)
        if step is None or len(grid) < 2 or self.resolution.tool_bound(grid[1] - grid[0]) <= step:
            return grid, on_grid
        tool = self._tool_positions(grid)
        chords = np.linalg.norm(np.diff(tool, axis=0), axis=1)
        pieces = np.maximum(1, np.ceil(chords / (step * (1 - TOOL_MARGIN)))).astype(int)
        if np.all(pieces == 1):
            return grid, on_grid
        starts = np.repeat(np.arange(len(pieces)), pieces)
        offsets = np.arange(len(starts)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
        fractions = (offsets / np.repeat(pieces, pieces))[:, None]
        points = grid[starts] + fractions * (grid[starts + 1] - grid[starts])
        return np.vstack((points, grid[-1:])), np.append(offsets == 0, True)

    def _tool_positions(self, qs: np.ndarray) -> np.ndarray:
        """The tool frame's position [m] at each row of ``qs`` (k x 3)."""
        model, data, frame = self._model, self._model_data, self.robot.ee_frame
        out = np.empty((len(qs), 3))
        for k, config in enumerate(self.configurations(qs).T):
            pin.forwardKinematics(model, data, config)
            out[k] = pin.updateFramePlacement(model, data, frame).translation
        return out


def _copy_requests(source: pin.GeometryData, target: pin.GeometryData) -> None:
    """Make ``target``'s requests answer as ``source``'s: exact as they are, and free of
    history (``collision_geometry.configure_requests``: coal's warm start made an
    answer depend on the configuration checked before)."""
    exact = all(request.enable_contact for request in source.collisionRequests)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the warm start's old switch
        for request in target.collisionRequests:
            request.enable_contact = exact
            request.enable_cached_gjk_guess = False
            request.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
