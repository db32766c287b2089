"""Which configurations and edges a planner may use: the collision model's batched check
at the edge resolution.

``ValidityChecker`` answers for one robot against itself and its workcell (the
pairs its ``CollisionModel`` chose, with the same exact requests) and against
the other robots of a cell, held where they stand while it plans: a
``collision.BatchCheck`` (Pinocchio's broad phase, batches stopping at the
first hit). An edge is checked as its ``EdgeResolution`` (below) says: its joint grid,
far end first and then coarse to fine, and then, if the tool travels more than
its step between grid points, the points cutting those intervals.

The checker is a snapshot: build a new one when the workcell or another robot
changes (about a millisecond; ``CollisionModel.revision`` counts the changes).

How finely a straight joint-space edge is checked (``EdgeResolution``): joint steps, tool
travel, lever arms. An edge is first cut into a *joint grid*: consecutive points differ by at most
``max_step`` on each joint (default 1 degree revolute, 5 mm prismatic). The
tool's travel is then bounded too (default 5 mm between checked points), in two
ways, cheapest first:

- ``lever_arms``: a bound, valid in every configuration, on how far the tool
  frame is from each joint's axis (the fixed link offsets after the joint,
  added up). A step ``dq`` moves the tool along a curve no longer than
  ``sum(lever_arm * |dq|)``; where that is already under the tool step (small
  wrist moves), the joint grid is enough and no kinematics is computed.
- otherwise the tool's positions at the grid points come from forward
  kinematics, and a grid interval whose chord is longer than the tool step
  (less ``TOOL_MARGIN``) is cut into equal parts (``ValidityChecker``).

Why FK rather than the lever bound alone: the bound assumes a stretched arm
with every joint's motion adding up, and checks 2.6 to 3.2 times more points
than the tool's real travel needs on the bundled arms (median over random
edges). Between two grid points (each joint within 1 degree) the tool's path is
its chord to within far less than the margin, so cutting by chords keeps every
piece under the tool step (``tests/planning`` measures it with dense FK).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
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
from c2rviz.robot import Robot

from .errors import BadPlanningSetting, checked_setting

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


Joints = Sequence[float] | np.ndarray
"""Chain values [rad or m]: a sequence or a 1-D array."""

MAX_STEP_RAD = math.radians(1.0)  # [rad] most a revolute joint moves between two checks
MAX_STEP_M = 0.005  # [m] most a prismatic joint moves between two checks
MAX_TOOL_STEP_M = 0.005  # [m] most the tool travels between two checks
TOOL_MARGIN = 0.05  # chords are cut at (1 - margin) of the tool step
RANGES = {  # setting -> (smallest, largest) accepted
    "max_step_rad": (1e-4, 0.2),
    "max_step_m": (1e-5, 0.1),
    "max_step": (1e-5, 0.2),
    "max_tool_step_m": (1e-4, 0.1),
}


@dataclass(frozen=True)
class EdgeResolution:
    """How finely an edge is checked (see the module).

    Attributes:
        max_step: Most a joint moves between checks, per joint [rad or m].
        max_tool_step_m: Most the tool travels between checks [m]; None: no bound.
        lever_arm: Bound on the tool's speed per unit speed of each joint [m/rad,
            1 for a prismatic joint] (``lever_arms``); empty: unknown.

    Raises:
        BadPlanningSetting: a step that is NaN, <= 0 or too large, or lever arms
            that do not match the joints.
    """

    max_step: tuple[float, ...]
    max_tool_step_m: float | None = None
    lever_arm: tuple[float, ...] = ()
    _inverse: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        low, high = RANGES["max_step"]
        steps = tuple(checked_setting("max_step", x, low, high, "rad or m") for x in self.max_step)
        if not steps:
            raise BadPlanningSetting("max_step", self.max_step, "give one step per joint")
        object.__setattr__(self, "max_step", steps)
        object.__setattr__(self, "_inverse", 1.0 / np.array(steps))
        if self.max_tool_step_m is not None:
            low, high = RANGES["max_tool_step_m"]
            tool = checked_setting("max_tool_step_m", self.max_tool_step_m, low, high, "m")
            object.__setattr__(self, "max_tool_step_m", tool)
        arms = tuple(float(x) for x in self.lever_arm)
        if arms and (len(arms) != len(steps) or not all(0 <= x < math.inf for x in arms)):
            valid = f"give {len(steps)} finite lever arms >= 0 [m/rad]"
            raise BadPlanningSetting("lever_arm", self.lever_arm, valid)
        object.__setattr__(self, "lever_arm", arms)

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.max_step)

    def grid(self, q0: Joints, q1: Joints) -> np.ndarray:
        """The joint grid of ``q0 -> q1`` [rad or m]: both ends included, in order ((k+1) x n)."""
        a, b = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
        count = max(1, math.ceil(float(np.max(np.abs(b - a) * self._inverse)) - 1e-9))
        return a + np.linspace(0.0, 1.0, count + 1)[:, None] * (b - a)

    def tool_bound(self, step: np.ndarray) -> float:
        """Most the tool can travel [m] over a joint step ``step`` (inf without lever arms)."""
        if not self.lever_arm:
            return math.inf
        return float(np.dot(np.abs(step), self.lever_arm))


def lever_arms(robot: Robot) -> tuple[float, ...]:
    """A bound, valid in every configuration, on the tool's speed per unit speed of each joint.

    For a revolute joint: the tool frame's largest distance from the joint's
    axis [m/rad], at most the lengths of the fixed offsets from the joint to the
    tool added up, plus the travel of any prismatic joint among them. For a
    prismatic joint: 1 (the tool moves as far as the joint).
    """
    model = robot.model
    ee = model.frames[robot.ee_frame]
    chain = {model.getJointId(joint.name): joint for joint in robot.joints}
    reach: dict[int, float] = {}
    tail = float(np.linalg.norm(ee.placement.translation))
    joint = ee.parentJoint
    while joint > 0:
        jm = model.joints[joint]
        if jm.shortname().startswith("JointModelP") and jm.nq == 1:
            if joint in chain:
                tail += max(abs(chain[joint].lower), abs(chain[joint].upper))
            else:  # off the chain: it stays at its neutral value
                tail += abs(float(robot.neutral[jm.idx_q]))
        reach[joint] = tail
        tail += float(np.linalg.norm(model.jointPlacements[joint].translation))
        joint = model.parents[joint]
    return tuple(
        1.0 if joint.prismatic else reach[model.getJointId(joint.name)] for joint in robot.joints
    )


def edge_resolution(
    robot: Robot,
    max_step_rad: float = MAX_STEP_RAD,
    max_step_m: float = MAX_STEP_M,
    max_tool_step_m: float | None = MAX_TOOL_STEP_M,
) -> EdgeResolution:
    """``robot``'s edge resolution: per joint steps and a tool-travel bound (see the module).

    Args:
        robot: The robot (which joints are prismatic; its lever arms).
        max_step_rad: Most a revolute joint moves between checks [rad].
        max_step_m: Most a prismatic joint moves between checks [m].
        max_tool_step_m: Most the tool travels between checks [m]; None: no bound.

    Raises:
        BadPlanningSetting: a step that is NaN, <= 0 or too large (names the range).
    """
    rad = checked_setting("max_step_rad", max_step_rad, *RANGES["max_step_rad"], "rad")
    metres = checked_setting("max_step_m", max_step_m, *RANGES["max_step_m"], "m")
    steps = tuple(metres if prismatic else rad for prismatic in robot.prismatic)
    return EdgeResolution(steps, max_tool_step_m, lever_arms(robot))


@lru_cache(maxsize=1024)
def coarse_first(count: int) -> np.ndarray:
    """An order of the indices 0..count-1 of an edge's points: the last, then halving the gaps.

    A blocked edge is then usually found blocked after a few checks.
    """
    if count <= 0:
        return np.zeros(0, dtype=int)
    order = [count - 1]
    queue = deque([(-1, count - 1)])  # open intervals of indices still to visit
    while queue:
        low, high = queue.popleft()
        if high - low >= 2:
            middle = (low + high) // 2
            order.append(middle)
            queue.extend(((low, middle), (middle, high)))
    return np.array(order, dtype=int)
