"""The world of the command process as the page process sees it (``--page-process``).

``MirrorWorld`` is a ``World`` built from a ``page_snapshot.Snapshot``: the same robots,
placed and posed as they are, with the same limits. It never moves on its own: the
frames that follow (``page_process``) pose it, say which robots move and how long
they have left (``_Travels``), and hand it the ghost's path as joint rows (``_Path``).
Its clock (``MirrorClock``) is the command process's, as last heard of.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from ..collision.workcell import WorkcellObject
from ..world.clock import Clock
from ..world.state import RobotState
from ..world.world import World
from .page_snapshot import Snapshot

__all__ = ["MirrorClock", "MirrorWorld"]


class MirrorClock(Clock):
    """The command process's clock, as last heard of, running on at real speed."""

    def __init__(self, t: float) -> None:
        self.offset = t - time.monotonic()

    def now(self) -> float:
        return time.monotonic() + self.offset

    def heard(self, t: float) -> None:
        """The command process's clock read ``t`` just now."""
        self.offset = t - time.monotonic()


class _Path:
    """A ghost's path as the command process sent it: joint rows (``ghost.tool_path``)."""

    def __init__(self, rows: list[list[float]]) -> None:
        self.joint_path = np.asarray(rows, dtype=float)
        self.arrival = 0.0


class _Travel:
    """A robot's motion as the command process last said: moving or not, its path."""

    def __init__(self) -> None:
        self.active = False
        self.path: _Path | None = None
        self.seconds_left = 0.0


class _Travels:
    """Stands in for ``world.moves.Travels``: what the page reads of it."""

    def __init__(self, names: Sequence[str]) -> None:
        self.by_robot = {name: _Travel() for name in names}

    def seconds_left(self, state: RobotState) -> float:
        return self.by_robot[state.name].seconds_left

    def now(self, state: RobotState) -> tuple[float, ...]:
        return state.q

    def stop_all(self) -> None:
        pass


class MirrorWorld(World):
    """The world of the command process, as the frames tell it; see the module docstring.

    Attributes:
        objects: Each robot's workcell objects (there is no collision model here).
    """

    def __init__(self, snap: Snapshot, hz: float) -> None:
        super().__init__(
            {name: r.robot for name, r in snap.robots.items()},
            clock=MirrorClock(snap.t),
            hz=1.0 / snap.frame_s,
            origins={name: r.origin for name, r in snap.robots.items()},
            limits={name: r.limits for name, r in snap.robots.items()},
        )
        self.travels = _Travels(list(snap.robots))  # type: ignore[assignment]
        self.observers = []  # no collision checks here: the scene, and a trail when on
        self.objects: dict[str, list[WorkcellObject]] = {}
        for name, r in snap.robots.items():
            state = self.robots[name]
            state.q, state.target, state.opening = r.q, r.target, r.opening
            state.tool, state.ghost = r.tool, r.ghost
            state.markers.extend(r.markers)
            self.objects[name] = list(r.objects)
            self.moved(name, r.moving, r.seconds_left)

    def moved(self, name: str, moving: bool, seconds_left: float) -> None:
        travel = self.travels.by_robot[name]
        travel.active = moving
        travel.seconds_left = seconds_left  # type: ignore[attr-defined]
