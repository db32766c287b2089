"""Inverse kinematics on pink and daqp (``solver``, ``chain``, ``tool_task``) and the
straight tool line (``line``). Pure: no asyncio, no clock.
"""

from .line import LineBlocked, StraightLine, plan_line
from .solver import IkSettings, IkSolver, Unreachable

__all__ = ["IkSettings", "IkSolver", "LineBlocked", "StraightLine", "Unreachable", "plan_line"]
