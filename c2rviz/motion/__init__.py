"""Moves that take time, pure (no asyncio, no clock of their own: times are the caller's):
the ruckig planner (``planner``), the joints' motion limits (``limits``), timed joint
points planned and checked whole (``trajectory``), and what any path played on the clock
offers, with the straight line's and the trajectory's plays (``path_play``).
"""

from .limits import MotionLimitError, MotionLimits, MotionPlanError, TrajectoryError, motion_limits
from .path_play import LinePlay, PathPlay, TrajectoryPlay, brake_limits, ramp_limits
from .planner import Motion
from .trajectory import PlannedTrajectory, plan_trajectory

__all__ = [
    "LinePlay",
    "Motion",
    "MotionLimitError",
    "MotionLimits",
    "MotionPlanError",
    "PathPlay",
    "brake_limits",
    "PlannedTrajectory",
    "TrajectoryError",
    "TrajectoryPlay",
    "motion_limits",
    "plan_trajectory",
    "ramp_limits",
]
