"""Inverse kinematics: a damped Newton descent over Pinocchio (``newton``) from ranked seeds
(``seeds``), refused early beyond the arm's reach (``reach``), pink and daqp only to find
a refused target's closest pose (``closest``); targets with or without an
orientation (``target``); and the straight tool line (``line``). Pure: no asyncio, no clock.
"""

from .line import LineBlocked, StraightLine, plan_line
from .solver import IkSettings, IkSolver
from .target import PointTarget, Target
from .unreachable import Unreachable

__all__ = [
    "IkSettings",
    "IkSolver",
    "LineBlocked",
    "PointTarget",
    "StraightLine",
    "Target",
    "Unreachable",
    "plan_line",
]
