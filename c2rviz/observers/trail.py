"""The trail: the path of the tool point as the arm actually moves, kept for drawing.

``TrailKeeper`` is one per world (the app makes it), an observer that
keeps, for every robot whose trail is on, the tool point (the robot's ``tool`` on
its end-effector link, as it is when the point is taken) in the robot's root frame
[m] (the world frame for a robot at the world's origin; the page draws it under the
robot's root) at most once per frame (``1/hz`` of the world's clock), so a flood of
commands costs one forward kinematics per frame, not one per command, and a move in
motion leaves its path at frame rate. The latest state of a frame is kept and added
when the points are read or the next frame is due, so the trail always ends where
the arm is.

A trail is bounded: at ``cap`` points it thins its older half (every other point goes)
instead of growing, so a long trail keeps its whole extent with the recent part dense.

For a view: poll ``changed`` (one counter for the world; it moves whenever anything a
view draws may have changed), then for each ``robot`` in ``robots()`` draw
``points(robot)`` (a copy) as one polyline, e.g. ``segments(robot)`` as one line-segment
batch.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..world.observer import Observer
from ..world.state import RobotState
from ..world.world import World

DEFAULT_TRAIL_POINTS = 20_000
"""Points a trail keeps at most (``trail_points`` in the ini)."""
MIN_TRAIL_POINTS = 16


class RobotTrail:
    """One robot's trail: up to ``cap`` points [m], oldest first."""

    def __init__(self, state: RobotState, cap: int, period_s: float) -> None:
        self.state = state
        self.cap = cap
        self.period_s = period_s
        self._points = np.empty((cap, 3))
        self._count = 0
        self._due = -np.inf  # clock time [s] when the next point may be added
        self._pending: Sequence[float] | None = None  # the latest state not yet added
        self.clears = 0
        """Times it was emptied (``trail clear``): a copy of it elsewhere (the page
        process's) clears its own when this moves."""

    def __len__(self) -> int:
        self._take_pending()
        return self._count

    def add(self, q: Sequence[float], t: float) -> None:
        """The arm is at ``q`` [rad or m] at clock time ``t`` [s]."""
        if t >= self._due:
            self._pending = None
            self._append(q)
            self._due = t + self.period_s
        else:
            self._pending = q

    def points(self) -> np.ndarray:
        """The trail, shape (n, 3), the robot's root frame [m], oldest first (a copy)."""
        self._take_pending()
        return self._points[: self._count].copy()

    def clear(self) -> None:
        self.clears += 1
        self._count = 0
        self._pending = None
        self._due = -np.inf

    def _take_pending(self) -> None:
        if self._pending is not None:
            q, self._pending = self._pending, None
            self._append(q)

    def _append(self, q: Sequence[float]) -> None:
        robot = self.state.robot
        point = (robot.base_placement * robot.ee_pose(q) * self.state.tool).translation
        if self._count and np.array_equal(self._points[self._count - 1], point):
            return  # standing still adds nothing
        if self._count == self.cap:
            self._thin()
        self._points[self._count] = point
        self._count += 1

    def _thin(self) -> None:
        """Drop every other point of the older half: 3/4 of the cap stays."""
        half = self.cap // 2
        older = self._points[:half:2].copy()
        newer = self._points[half : self._count].copy()
        self._points[: len(older)] = older
        self._points[len(older) : len(older) + len(newer)] = newer
        self._count = len(older) + len(newer)


class TrailKeeper(Observer):
    """The trails of one world's robots (only those turned on are kept)."""

    def __init__(self, world: World, cap: int = DEFAULT_TRAIL_POINTS) -> None:
        if cap < MIN_TRAIL_POINTS:
            raise ValueError(f"a trail needs at least {MIN_TRAIL_POINTS} points, got {cap}")
        self.world = world
        self.cap = cap
        self.trails: dict[str, RobotTrail] = {}
        """The robots whose trail is on, by name."""
        self.changed = 0
        """Moves whenever a trail may look different (a point, on, off, clear)."""

    # What the `trail` verb does.

    def start(self, robot: str) -> None:
        """A fresh trail for ``robot``, from where the arm is now."""
        state = self.world.state(robot)
        trail = RobotTrail(state, self.cap, self.world.frame_s)
        trail.add(state.q, self.world.clock.now())
        if not self.trails:
            self.world.add_observers([self])
        self.trails[robot] = trail
        self.changed += 1

    def stop(self, robot: str) -> None:
        """Remove ``robot``'s trail."""
        if self.trails.pop(robot, None) is not None:
            self.changed += 1
            if not self.trails:
                self.world.remove_observer(self)

    def clear(self, robot: str) -> None:
        """Empty ``robot``'s trail; it goes on from where the arm is."""
        trail = self.trails.get(robot)
        if trail is not None:
            trail.clear()
            trail.add(self.world.state(robot).q, self.world.clock.now())
            self.changed += 1

    # What a view reads.

    def robots(self) -> list[str]:
        """The robots whose trail is on."""
        return list(self.trails)

    def points(self, robot: str) -> np.ndarray:
        """``robot``'s trail, shape (n, 3), its root frame [m], oldest first; (0, 3) when off."""
        trail = self.trails.get(robot)
        return trail.points() if trail is not None else np.empty((0, 3))

    def segments(self, robot: str) -> np.ndarray:
        """The trail as line segments, shape (n - 1, 2, 3) [m]: one batch to draw."""
        points = self.points(robot)
        return np.stack([points[:-1], points[1:]], axis=1)

    # The world's effects.

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        trail = self.trails.get(robot)
        if trail is not None:
            trail.add(q, t)
            self.changed += 1
