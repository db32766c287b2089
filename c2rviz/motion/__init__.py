"""Moves that take time, pure (no asyncio, no clock of their own: times are the caller's):
the ruckig planner (``planner``), the joints' motion limits (``limits``), a joint
path played along its own timing (``line_play``), timed joint points planned and
checked whole (``trajectory``), and what any path played on the clock offers, with the
trajectory's play (``path_play``).
"""

from .limits import MotionLimitError, MotionLimits, motion_limits
from .line_play import LinePlay, brake_limits, ramp_limits
from .path_play import PathPlay, TrajectoryPlay
from .planner import Motion, MotionPlanError
from .trajectory import PlannedTrajectory, TrajectoryError, plan_trajectory

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
