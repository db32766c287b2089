"""The one shared state: robots by name (``state``), the clock every part asks
(``clock``), the interface observers and views implement (``observer``), moves
that take time (``moves``), collisions checked at frame rate (``live_collisions``) and
``World`` itself, which applies checked changes and fans their effects out.
"""

from .observer import NullScene, Observer, RecordingScene, Scene
from .state import MAX_MARKERS, Marker, RobotState
from .world import World

__all__ = [
    "MAX_MARKERS",
    "Marker",
    "NullScene",
    "Observer",
    "RecordingScene",
    "RobotState",
    "Scene",
    "World",
]
