"""Which configurations and edges a planner may use: the collision model's batched check
at the edge resolution.

``ValidityChecker`` answers for one robot against itself and its workcell (the
pairs its ``CollisionModel`` chose, with the same exact requests) and against
the other robots of a cell, held where they stand while it plans: a
``collision.BatchCheck`` (Pinocchio's broad phase, batches stopping at the
first hit). An edge is checked as ``edge_resolution.py`` says: its joint grid,
far end first and then coarse to fine, and then, if the tool travels more than
its step between grid points, the points cutting those intervals.

The checker is a snapshot: build a new one when the workcell or another robot
changes (about a millisecond; ``CollisionModel.revision`` counts the changes).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from typing import cast

import numpy as np
import pinocchio as pin

from c2rviz.collision import (
    BatchCheck,
    CheckGeometry,
    CollisionModel,
    Pair,
    PlacedShape,
    placed_shapes,
)

from .edge_resolution import TOOL_MARGIN, EdgeResolution, Joints, coarse_first, edge_resolution

__all__ = ["PlacedShape", "ValidityChecker", "robot_shapes"]

robot_shapes = placed_shapes
"""Every collision shape of a robot at ``q``, placed in the cell (``collision.placed_shapes``)."""


class ValidityChecker:
    """Whether configurations and edges of one robot are free of collisions (one thread).

    Attributes:
        collision: The robot's collision model (self pairs and workcell objects).
        robot: Its robot.
        resolution: How finely edges are checked.
        batch: The batched check underneath (its ``names`` are the pairs checked).
        source: The collision model's checks it copied.
        revision: Their revision.
        others: The other robots' shapes it holds as obstacles, placed in the cell.
        origin: Where this robot's root stands in the cell (None: at its origin).
    """

    def __init__(
        self,
        collision: CollisionModel,
        others: Sequence[PlacedShape] = (),
        *,
        origin: pin.SE3 | None = None,
        resolution: EdgeResolution | None = None,
        without: Collection[Pair] = (),
        only: Collection[Pair] | None = None,
        source: CheckGeometry | None = None,
    ) -> None:
        """Snapshot ``collision``'s checks and add the other robots' shapes as fixed obstacles.

        Args:
            collision: The planning robot's collision model.
            others: Shapes of the other robots of the cell, placed in the cell
                (``robot_shapes``); each is checked against every moving link.
            origin: Placement of this robot's model root frame in the cell
                (identity if None) [m].
            resolution: Edge resolution (``edge_resolution(robot)`` if None).
            without: Pairs not checked (a guarded move may leave a contact).
            only: If given, the only pairs checked.
            source: The model's checks to copy (``collision.check_geometry()`` if None).
        """
        robot = collision.robot
        self.collision = collision
        self.robot = robot
        self.resolution = resolution if resolution is not None else edge_resolution(robot)
        self.others = tuple(others)
        self.origin = origin
        source = source if source is not None else collision.check_geometry()
        self.source = source
        self.revision = source.revision
        self.batch = BatchCheck(
            robot,
            source,
            others,
            origin=origin,
            without=frozenset(without),
            only=None if only is None else frozenset(only),
        )
        self._model = robot.model
        self._model_data = robot.model.createData()

    def variant(
        self, *, without: Collection[Pair] = (), only: Collection[Pair] | None = None
    ) -> ValidityChecker:
        """The same checks (model, others, resolution), less ``without`` or only ``only``."""
        return ValidityChecker(
            self.collision,
            self.others,
            origin=self.origin,
            resolution=self.resolution,
            without=without,
            only=only,
            source=self.source,
        )

    @property
    def checks(self) -> int:
        """Configurations checked so far (every point of every batch looked at)."""
        return self.batch.checks

    def configurations(self, qs: np.ndarray | Sequence[Joints]) -> np.ndarray:
        """Pinocchio configurations (``nq`` x k) of chain values ``qs`` (k x n) [rad or m]."""
        return self.batch.configurations(cast(np.ndarray, qs))

    def first_invalid(self, qs: np.ndarray | Sequence[Joints]) -> int | None:
        """Index of the first row of ``qs`` (k x n) [rad or m] in collision, or None.

        The rows are checked in order, stopping at the first hit.
        """
        return self.batch.first_invalid(cast(np.ndarray, qs))

    def is_valid(self, q: Joints) -> bool:
        """True when ``q`` [rad or m] collides with nothing checked."""
        return self.batch.is_valid(cast(np.ndarray, q))

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
        return self.batch.describe(cast(np.ndarray, q))

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
