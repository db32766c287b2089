"""A recording's rosbag2 bag: the robots' topics as ROS tools read them, beside NAME.txt/.csv.

``BagRecorder(world, robots, path, t0, on_failed)`` writes one bag folder
through ``ros.BagWriter`` (MCAP storage, CDR, ROS 2 Humble types) for one robot,
or for several robots of a cell at once:

- each robot's ``[/NS]/robot_description`` (its URDF) and its fixed joints on
  ``/tf_static``, once, at time 0 (both transient-local); in a cell also the
  robot's place: ``world`` -> ``NS/ROOT`` at its origin;
- with every frame the robot's ``Recorder`` writes (``frame``, at the CSV's time):
  ``[/NS]/joint_states`` (every moving joint of the URDF by name; positions, and
  velocities while a move runs: the planner's for a joint move, the change over
  the last frame for a path such as ``movel``; none at rest) and ``/tf`` (each
  moving joint's parent -> child transform);
- ``[/NS]/visualization_marker_array``, as they change: the markers (namespace
  ``markers``, ids in the order they were dropped; a marker past
  ``MAX_MARKERS`` deletes the oldest, ``clear`` deletes each one) and the
  workcell objects (namespace ``workcell``, one id per object name: ADD when set
  or changed, DELETE when removed), in the frames the page shows them in;
- ``/c2rviz/commands``: each accepted command as ``SOURCE: LINE``, and
  ``/c2rviz/replies``: each reply as ``SOURCE: LINE -> REPLY``, from every source
  (as NAME.txt's ``# sources``); the lines of one frame (``1/hz``) are one message,
  a line each, stamped with the first one's time and written when the frame is over.

NS is the robot's name in a cell (``/left/joint_states``, frames
``left/base_link``), none for a robot alone. Every stamp, header and log time
alike, is the recording's time: seconds [s] from its start on the world's clock
(the ``time`` column of NAME.csv). A write error stops the bag where it stands
(``BagWriter``'s end state) and calls ``on_failed`` once.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import pinocchio as pin

from ..ros import markers as mk
from ..ros.bag_writer import BagWriter
from ..ros.messages import Msg
from ..ros.robot_bag import BagRobot
from ..world.clock import Clock, Timer
from ..world.effects import Observer
from ..world.state import MAX_MARKERS, Marker, RobotState
from ..world.world import World

if TYPE_CHECKING:
    from ..collision.workcell import WorkcellObject
    from .recorder import Recorder

__all__ = ["MARKER_SIZE_M", "WORLD_FRAME", "BagRecorder", "namespaces"]

WORLD_FRAME = "world"
"""The cell's frame in a bag of a cell."""
MARKER_SIZE_M = 0.03
"""A marker's size as the page draws it (``view.markers``) [m]."""
_S = MARKER_SIZE_M
_SCALES = {  # visualization_msgs scale of each marker shape, as the page draws it
    "sphere": (_S, _S, _S),
    "cube": (_S, _S, _S),
    "cylinder": (2 * _S / 3, 2 * _S / 3, _S),
    "arrow": (1.7 * _S, _S / 4, 2 * _S / 3),
}
_NOT_ROS = re.compile(r"[^A-Za-z0-9_]")


def namespaces(names: Sequence[str]) -> dict[str, str]:
    """A ROS namespace for each robot name, unique: characters other than letters, digits
    and ``_`` become ``_``, a leading digit or ``_`` gets ``r`` before it."""
    out: dict[str, str] = {}
    for name in names:
        ns = _NOT_ROS.sub("_", name)
        ns = ns if ns[:1].isalpha() else "r" + ns
        base, k = ns, 1
        while ns in out.values():
            k += 1
            ns = f"{base}_{k}"
        out[name] = ns
    return out


@dataclass(eq=False)
class _Arm:
    """One robot of the bag and what its markers and objects are in it."""

    state: RobotState
    bag: BagRobot
    marker_frame: str
    object_frame: str
    live: deque[int] = field(default_factory=deque)  # marker ids shown, oldest first
    next_id: int = 0
    objects: dict[str, WorkcellObject] = field(default_factory=dict)
    object_ids: dict[str, int] = field(default_factory=dict)
    last: tuple[float, Sequence[float]] | None = None  # the previous frame: (t [s], q)


class _Lines:
    """The lines of a text topic within one frame, written as one ``String`` when the frame
    is over (a flood of commands costs a list append each, not a bag message each)."""

    def __init__(self, writer: BagWriter, topic: str, clock: Clock, t0: float, period_s: float):
        self.writer = writer
        self.topic = topic
        self.clock = clock
        self.t0 = t0
        self.period_s = period_s
        self.t_s = 0.0  # the first line's time [s from the start]
        self.lines: list[str] = []
        self.timer: Timer | None = None

    def add(self, text: str) -> None:
        if not self.lines:
            now = self.clock.now()
            self.t_s = max(0.0, now - self.t0)
            self.timer = self.clock.call_at(now + self.period_s, self.flush)
        self.lines.append(text)

    def flush(self) -> None:
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None
        if self.lines:
            self.writer.text(self.topic, self.t_s, "\n".join(self.lines))
            self.lines = []


class BagRecorder(Observer):
    """The bag of one recording (one robot, or a cell's robots); on the asyncio thread."""

    def __init__(
        self,
        world: World,
        robots: Sequence[str],
        path: Path,
        t0: float,
        on_failed: Callable[[BagRecorder, str], None],
    ) -> None:
        """Create the bag folder ``path`` and write what is there at time 0.

        Args:
            world: What is recorded.
            robots: The robots recorded, by name in the world.
            path: The bag folder to create (its name names the ``.mcap``).
            t0: The recording's start on the world's clock [s].
            on_failed: Called once, on the asyncio thread, when a write error stops it.

        Raises:
            BagError: the folder cannot be created.
            RosError: a robot's URDF cannot be read for TF.
        """
        self.world = world
        self.path = path
        self.t0 = t0
        self.on_failed = on_failed
        self.closed = False
        self.peers: list[Recorder] = []
        """The recorders whose frames come here (their due frames are written first)."""
        self.writer = BagWriter(path, on_error=self._failed)
        lines = (world.clock, t0, world.frame_s)
        self.commands = _Lines(self.writer, "/c2rviz/commands", *lines)
        self.replies = _Lines(self.writer, "/c2rviz/replies", *lines)
        in_cell = len(world.robots) > 1
        spaces = namespaces(list(world.robots)) if in_cell else {}
        self.arms: dict[str, _Arm] = {}
        for name in robots:
            state = world.state(name)
            ns = spaces.get(name, "")
            arm = BagRobot(self.writer, state.robot, ns)
            placed = in_cell or (not state.origin.isIdentity() and arm.tree.root != WORLD_FRAME)
            arm.start(0.0, _xyz_xyzw(state.origin) if placed else None, WORLD_FRAME)
            prefix = ns + "/" if ns else ""
            self.arms[name] = _Arm(
                state,
                arm,
                WORLD_FRAME if placed else arm.tree.root,
                prefix + state.robot.base,
            )
            for marker in state.markers:
                self.on_marker(name, marker)
            model = world.contacts.models.get(name)
            if model is not None:
                self.on_objects(name, model.object_list())

    def _t(self) -> float:
        return max(0.0, self.world.clock.now() - self.t0)

    # Frames, from the recorders.

    def frame(self, robot: str, t_s: float, at: float, q: Sequence[float]) -> None:
        """Robot ``robot`` at ``q`` [rad or m] at ``t_s`` [s from the start], clock ``at``."""
        arm = self.arms.get(robot)
        if arm is None or self.closed:
            return
        for peer in self.peers:  # a cell's /tf stays in time order
            if peer.robot != robot:
                peer.flush_due(at)
        arm.bag.frame(t_s, q, self._velocity(arm, t_s, at, q))
        arm.last = (t_s, q)

    def _velocity(self, arm: _Arm, t_s: float, at: float, q: Sequence[float]) -> Sequence[float]:
        travel = self.world.travel(arm.state.name)
        if not travel.active:
            return ()
        if travel.path is None:
            return travel.motion.sample(at)[1]
        if arm.last is None or t_s <= arm.last[0]:
            return ()
        t_before, q_before = arm.last
        return [(a - b) / (t_s - t_before) for a, b in zip(q, q_before)]

    # The world's other effects.

    def on_marker(self, robot: str, marker: Marker) -> None:
        arm = self.arms.get(robot)
        if arm is None or self.closed:
            return
        t_s = self._t()
        out = []
        if len(arm.live) >= MAX_MARKERS:  # the world dropped its oldest marker
            out.append(mk.delete_marker(t_s, arm.marker_frame, "markers", arm.live.popleft()))
        out.append(_marker(t_s, arm.marker_frame, arm.next_id, marker))
        arm.live.append(arm.next_id)
        arm.next_id += 1
        self.writer.markers(t_s, mk.marker_array(out), arm.bag.namespace)

    def on_clear_markers(self, robot: str) -> None:
        arm = self.arms.get(robot)
        if arm is None or self.closed or not arm.live:
            return
        t_s = self._t()
        gone = [mk.delete_marker(t_s, arm.marker_frame, "markers", k) for k in arm.live]
        arm.live.clear()
        self.writer.markers(t_s, mk.marker_array(gone), arm.bag.namespace)

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        arm = self.arms.get(robot)
        if arm is None or self.closed:
            return
        t_s = self._t()
        now = {obj.name: obj for obj in objects}
        out = [
            mk.delete_marker(t_s, arm.object_frame, "workcell", arm.object_ids[name])
            for name in arm.objects
            if name not in now
        ]
        for name, obj in now.items():
            if arm.objects.get(name) is not obj:
                number = arm.object_ids.setdefault(name, len(arm.object_ids))
                out.append(_object(t_s, arm.object_frame, number, obj))
        arm.objects = now
        if out:
            self.writer.markers(t_s, mk.marker_array(out), arm.bag.namespace)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        if accepted and not self.closed:
            self.commands.add(f"{source}: {line}")

    def on_reply(self, source: str, line: str, reply: str) -> None:
        if not self.closed:
            self.replies.add(f"{source}: {line} -> {reply}")

    # The end.

    def _failed(self, error: str) -> None:
        self.closed = True
        for lines in (self.commands, self.replies):
            if lines.timer is not None:
                lines.timer.cancel()
        self.on_failed(self, error)

    def stop(self) -> None:
        """Write what waits and take no more (on the asyncio thread); ``close`` ends the bag."""
        if not self.closed:
            self.commands.flush()
            self.replies.flush()
        self.closed = True

    def close(self) -> str | None:
        """Write the bag's summary and metadata (blocking: for a thread); return why it
        stopped early, if it did."""
        self.closed = True
        self.writer.close()
        return self.writer.error


def _xyz_xyzw(placement: pin.SE3) -> tuple[Sequence[float], Sequence[float]]:
    x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(placement).tolist()
    return (x, y, z), (qx, qy, qz, qw)


def _marker(t_s: float, frame: str, number: int, marker: Marker) -> Msg:
    w, x, y, z = marker.wxyz
    return mk.marker(
        t_s,
        frame,
        "markers",
        number,
        mk.SHAPES[marker.shape],
        marker.position,
        (x, y, z, w),
        _SCALES.get(marker.shape, (_S, _S, _S)),
        (*marker.rgb, 1.0),
    )


def _object(t_s: float, frame: str, number: int, obj: WorkcellObject) -> Msg:
    translation, quat = _xyz_xyzw(obj.placement)
    uri = obj.mesh_path.as_uri() if obj.mesh_path is not None else ""
    return mk.object_marker(
        t_s, frame, "workcell", number, obj.shape, obj.size, translation, quat, obj.rgba, uri
    )
