"""Collision-free paths: OMPL plans them, the collision model checks them, ruckig times them.

``ValidityChecker`` (``validity.py``) checks one robot against itself, its
workcell and the other robots of a cell, at its edge resolution
(``EdgeResolution``, there too); ``plan_for``/``plan_path`` (``ompl_planner.py``) plan
with RRT-Connect and shorten the path; ``time_path`` (``timing.py``) turns the
waypoints into a motion that stays on them. Several IK answers of a
pose to plan to, and a move checked or planned off the event loop with the guard's
path check (``guarded_move.py``: contacts at the start may be left) build on them;
``errors.py`` holds the planning errors and ``Cancel``, a plan's stop flag. No asyncio
and no world here: the caller owns the clock.
"""

from .errors import (
    BadPlanningSetting,
    GoalCollides,
    NoPathFound,
    NoWayAround,
    OutOfLimits,
    PathCheckFailed,
    PlanningError,
    StartCollides,
)
from .guarded_move import (
    PLAN_MODES,
    CheckedMove,
    MoveChecker,
    MoveRequest,
    first_blocked,
    goal_candidates,
    path_points,
)
from .ompl_planner import MAX_TIMEOUT_S, SEEDS, EdgeCheck, PlannedPath, plan_for, plan_path
from .timing import TimedPath, TimingFailed, time_path
from .validity import (
    MAX_STEP_M,
    MAX_STEP_RAD,
    MAX_TOOL_STEP_M,
    EdgeResolution,
    PlacedShape,
    ValidityChecker,
    edge_resolution,
    lever_arms,
    robot_shapes,
)

__all__ = [
    "PLAN_MODES",
    "SEEDS",
    "CheckedMove",
    "MoveChecker",
    "MoveRequest",
    "NoWayAround",
    "first_blocked",
    "goal_candidates",
    "path_points",
    "MAX_STEP_M",
    "MAX_STEP_RAD",
    "MAX_TIMEOUT_S",
    "MAX_TOOL_STEP_M",
    "BadPlanningSetting",
    "EdgeCheck",
    "EdgeResolution",
    "GoalCollides",
    "NoPathFound",
    "OutOfLimits",
    "PathCheckFailed",
    "PlacedShape",
    "PlannedPath",
    "PlanningError",
    "StartCollides",
    "TimedPath",
    "TimingFailed",
    "ValidityChecker",
    "edge_resolution",
    "lever_arms",
    "plan_for",
    "plan_path",
    "robot_shapes",
    "time_path",
]
