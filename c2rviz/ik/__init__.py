"""Inverse kinematics: a damped Newton descent over Pinocchio (``newton``) from ranked seeds
(``solver``), refused early beyond the arm's reach (``chain``), pink and daqp only to find
a refused target's closest pose (``closest``); targets with or without an
orientation and the refusal of one (``chain``); and the straight tool line (``line``).
Pure: no asyncio, no clock.
"""

from .chain import PointTarget, Target, Unreachable
from .line import LineBlocked, StraightLine, plan_line
from .solver import IkSettings, IkSolver

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
