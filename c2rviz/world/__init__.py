"""The one shared state: robots by name (``state``), the clock every part asks
(``clock``), the effect interface observers and views implement (``effects``), moves
that take time (``moves``), collisions checked at frame rate (``live_collisions``) and
``World`` itself, which applies checked changes and fans their effects out.
"""

from .effects import MAX_MARKERS, Marker, NullScene, Observer, RecordingScene, Scene
from .world import RobotState, World

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
