"""Collision checking on coal: a robot's collision model and its pairs (``model``,
``geometry``, SRDF too), the workcell's objects (``workcell``), and a robot's path
against the other robots of a cell (``other_robots``). Pure: no asyncio.
"""

from .geometry import Pair, read_srdf
from .model import CollisionError, CollisionModel, segment
from .workcell import MAX_OBJECTS, WorkcellObject

__all__ = [
    "CollisionError",
    "CollisionModel",
    "MAX_OBJECTS",
    "Pair",
    "WorkcellObject",
    "read_srdf",
    "segment",
]
