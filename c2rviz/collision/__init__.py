"""Collision checking on coal: a robot's collision model and its pairs (``model``,
``geometry``, SRDF too), the workcell's objects (``workcell``), and a robot's path
against the other robots of a cell (``other_robots``), and a fast batched check
for a thread of one's own (``batch``). Pure: no asyncio.
"""

from .batch import BatchCheck, CheckGeometry, PlacedShape
from .geometry import CollisionError, Pair, read_srdf
from .model import CollisionModel, segment
from .other_robots import OtherRobot, first_hit_between, pairs_between, placed_shapes
from .workcell import MAX_OBJECTS, WorkcellObject

__all__ = [
    "BatchCheck",
    "CheckGeometry",
    "CollisionError",
    "CollisionModel",
    "MAX_OBJECTS",
    "OtherRobot",
    "Pair",
    "PlacedShape",
    "WorkcellObject",
    "first_hit_between",
    "pairs_between",
    "placed_shapes",
    "read_srdf",
    "segment",
]
