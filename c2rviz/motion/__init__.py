"""Moves that take time, pure (no asyncio, no clock of their own: times are the caller's):
the ruckig planner (``planner``), the joints' motion limits (``limits``) and a joint
path played along its own timing (``line_play``), and what any path played on the
clock offers (``path_play``).
"""

from .limits import MotionLimitError, MotionLimits, motion_limits
from .line_play import LinePlay, brake_limits, ramp_limits
from .path_play import PathPlay
from .planner import Motion, MotionPlanError

__all__ = [
    "LinePlay",
    "Motion",
    "MotionLimitError",
    "MotionLimits",
    "MotionPlanError",
    "PathPlay",
    "brake_limits",
    "motion_limits",
    "ramp_limits",
]
