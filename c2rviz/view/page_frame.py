"""What one frame to the page process carries: the notes the world's effects leave, and
the ``frame`` message made of them (``--page-process``; ``page_link`` sends it); and the
world those frames pose in the page process (``MirrorWorld``).

``FrameNotes`` is the scene the world tells (``Scene``): each effect is noted in O(1)
(a joint sample, a robot changed, an event in order, parts, goals or cameras changed, a
robot's faults changed) and asks for a frame (``request``). ``frame`` then makes one
message: each changed robot's samples and state, then the events, then the newest lines
said since the last frame (as many as the 'last commands' readout keeps: every line is
counted, but a flood of them is not a flood of events), then the parts, goals, cameras and
fault banners as rows (``page_snapshot``) when they changed, the ghost's path when it
changed, and the trails when one was turned on or off or cleared.

``MirrorWorld`` is the world of the command process as the page process sees it: a
``World`` built from a ``page_snapshot.Snapshot``: the same robots, placed and posed as
they are, with the same limits. It never moves on its own: the frames that follow
(``page_process``) pose it, say which robots move and how long they have left
(``_Travels``), and hand it the ghost's path as joint rows (``_Path``). Its clock
(``MirrorClock``) is the command process's, as last heard of.
"""

from __future__ import annotations

import itertools
import pickle
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..errors import C2rvizError, PathCollides
from ..session.services import Services
from ..session.session import Session
from ..world.cameras import Camera
from ..world.clock import Clock
from ..world.observer import Scene
from ..world.part_rules import Goal
from ..world.parts import Part
from ..world.state import Marker, RobotState
from ..world.world import World
from .page_snapshot import Snapshot, camera_rows, fault_banner, goal_rows, part_rows, trail_state

SAMPLES_KEPT = 256
"""Joint samples of one robot kept for one frame (the newest; a flood of ``joints``
lines is thinned for the page's plots, never for the robot)."""
PATH_ROWS = 128
"""Rows a ghost's timed path is sampled at (``ghost.PATH_POINTS // 2``, as the page does;
not imported: ``ghost`` loads viser, which this process never needs)."""


class FrameNotes(Scene):
    """What changed since the last frame; see the module docstring.

    Attributes:
        sessions: The page's ``Session`` per robot (source ``page``).
        on_air: Whether a page process listens (effects are noted only then).
    """

    def __init__(self, services: Services, sessions: dict[str, Session], keep: int) -> None:
        """Notes for the robots of ``services``' world; ``keep``: last commands kept."""
        self.services = services
        self.world = world = services.world
        self.sessions = sessions
        self.on_air = False
        self.request: Callable[[], None] = lambda: None
        """Asks for a frame soon (``page_link`` sets it)."""
        self._samples: dict[str, deque[list[float]]] = {
            name: deque(maxlen=SAMPLES_KEPT) for name in world.robots
        }
        self._dirty: set[str] = set()
        self._events: list[list[Any]] = []
        self.commands: deque[tuple[str, bool]] = deque(maxlen=keep)
        self._said = 0  # commands told since the last frame (the newest ``keep`` go)
        self._trails: list[list[Any]] = []
        self._paths: dict[str, object] = {}  # the path each robot's ghost was last sent
        self._parts = self._goals = self._cameras = False  # changed since the last frame
        self._faults: set[str] = set()

    def fresh(self) -> None:
        """A new page process has the world as it is now: note only what follows."""
        self.drop()
        self._trails = trail_state(self.services)
        self._paths.clear()
        self._dirty.update(self.world.robots)  # the first frame says each ghost's path
        self.on_air = True

    def drop(self) -> None:
        """Forget what was noted (the page falls behind: a snapshot will say it all)."""
        for samples in self._samples.values():
            samples.clear()
        self._dirty.clear()
        self._events.clear()
        self._said = 0
        self._parts = self._goals = self._cameras = False
        self._faults.clear()

    # the Observer protocol (asyncio thread, O(1) each)

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        self._samples[robot].append([t, *q])
        self._dirty.add(robot)
        self.request()

    def on_gripper(self, robot: str, opening: float, t: float) -> None:
        self._dirty.add(robot)
        self.request()

    def on_motion(self, robot: str, t: float) -> None:
        self._dirty.add(robot)
        self.request()

    def on_arrived(self, robot: str) -> None:
        self.on_motion(robot, 0.0)

    def on_stopped(self, robot: str) -> None:
        self.on_motion(robot, 0.0)

    def on_marker(self, robot: str, marker: Marker) -> None:
        self._event(["marker", robot, marker.position, marker.wxyz, marker.rgb, marker.shape])

    def on_clear_markers(self, robot: str) -> None:
        self._event(["clear", robot])

    def on_clients(self, count: int) -> None:
        self._event(["clients", count])

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.commands.appendleft((line, accepted))
        if self.on_air:  # one count per line: the frame says the newest ``keep`` of them
            self._said += 1
            self.request()

    def on_tool(self, robot: str, tool: pin.SE3) -> None:
        self._event(["tool", robot, tool.homogeneous.ravel().tolist()])

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        self._event(["objects", robot, pickle.dumps(list(objects))])

    def on_collisions(self, robot: str, pairs: Sequence[tuple[str, str]]) -> None:
        self._event(["collisions", robot, [list(p) for p in pairs]])

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        pair: list[str] | None = None
        target: list[float] | None = None
        if isinstance(error, PathCollides):
            pair = list(error.pair)
            target = list(error.target) if error.target is not None else None
        self._event(["refused", robot, source, line, str(error), pair, target])

    def on_ghost(self, robot: str, shown: bool) -> None:
        self._event(["ghost", robot, shown])

    def on_fault(self, robot: str, text: str) -> None:
        if self.on_air:
            self._faults.add(robot)
            self.request()

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        if self.on_air:
            self._parts = True  # rows made once per frame, however many moves came
            self.request()

    def on_goals(self, goals: Sequence[Goal]) -> None:
        if self.on_air:
            self._goals = True
            self.request()

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        if self.on_air:
            self._cameras = True
            self.request()

    def _event(self, event: list[Any]) -> None:
        if self.on_air:
            self._events.append(event)
            self.request()

    # the frame

    def frame(self) -> list[Any]:
        """The ``frame`` message of what changed since the last; the notes start again."""
        world = self.world
        robots = []
        for name in self._dirty:
            state = world.robots[name]
            samples = self._samples[name]
            moving = world.moving(name)
            robots.append(
                [
                    name,
                    list(samples),
                    state.opening,
                    state.target,
                    moving,
                    world.travels.seconds_left(state),
                    self.sessions[name].speed,
                ]
            )
            samples.clear()
            path = world.travel(name).path if moving else None
            if path is not self._paths.get(name):
                self._paths[name] = path
                self._events.append(["path", name, path_rows(path, world.clock.now())])
        self._dirty.clear()
        events, self._events = self._events, []
        if self._said:
            said = itertools.islice(self.commands, min(self._said, len(self.commands)))
            events.append(["commands", [[line, accepted] for line, accepted in said]])
            self._said = 0
        if self._parts:
            events.append(["parts", part_rows(world.parts.parts.all()), world.clock.now()])
        if self._goals:
            events.append(["goals", goal_rows(world.parts.goals.all())])
        if self._cameras:
            events.append(["cameras", camera_rows(world.cameras.all())])
        for name in sorted(self._faults):
            events.append(["fault", name, fault_banner(world, name)])
        self._parts = self._goals = self._cameras = False
        self._faults.clear()
        trails = trail_state(self.services)
        if trails != self._trails:
            self._trails = trails
            events.append(["trails", trails])
        return ["frame", world.clock.now(), robots, events]


def path_rows(path: Any, now: float) -> list[list[float]] | None:
    """The joint rows of a ghost's path (``ghost.tool_path`` draws them), or None."""
    if path is None:
        return None
    rows = getattr(path, "joint_path", None)
    if rows is None:
        rows = getattr(path, "qs", None)
    if rows is None or len(rows) < 2:
        times = np.linspace(now, max(float(path.arrival), now), PATH_ROWS)
        rows = [path.sample(float(t)) for t in times]
    return np.asarray(rows, dtype=float).tolist()  # type: ignore[no-any-return]


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
