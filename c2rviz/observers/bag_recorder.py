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
- the parts (``bag_topics``): each one's frame ``parts/NAME`` on ``/tf`` as they move,
  and a marker of it (namespace ``parts``) on the first robot's marker topic;
- each logical camera's reports (``camera_feed``): ``/c2rviz/cameras/NAME``
  (``geometry_msgs/msg/PoseArray`` in the frame ``cameras/NAME``) at its rate on the
  world's clock, and its frames on ``/tf`` (``cameras/NAME``, ``cameras/NAME/PART``);
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

import logging
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import pinocchio as pin

from ..ros import messages as mk
from ..ros.bag_writer import BagRobot, BagWriter
from ..ros.messages import INT32, Msg, tf_message, transforms
from ..world.cameras import Camera, Seen
from ..world.observer import Observer
from ..world.parts import Part
from ..world.state import MAX_MARKERS, Marker, RobotState
from ..world.world import World
from .bag_topics import (
    PartFrames,
    TextLines,
    marker_message,
    namespaces,
    object_message,
    part_transforms,
    xyz_xyzw,
)
from .camera_feed import CAMERA_TOPIC, POSE_ARRAY, CameraFeed, camera_items, pose_array

if TYPE_CHECKING:
    from ..collision.workcell import WorkcellObject
    from .recorder import Recorder


log = logging.getLogger("c2rviz.record")

WORLD_FRAME = "world"
"""The cell's frame in a bag of a cell."""


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
    object_ids: dict[str, int] = field(default_factory=dict)  # of the objects there now
    next_object: int = 0
    last: tuple[float, Sequence[float]] | None = None  # the previous frame: (t [s], q)


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
        lines = (world.clock, t0, world.frame_s, self._broken)
        self.error: str | None = None
        """Why the bag stopped early, if it did."""
        self.commands = TextLines(self.writer, "/c2rviz/commands", *lines)
        self.replies = TextLines(self.writer, "/c2rviz/replies", *lines)
        in_cell = len(world.robots) > 1
        spaces = namespaces(list(world.robots)) if in_cell else {}
        self.arms: dict[str, _Arm] = {}
        for name in robots:
            state = world.state(name)
            ns = spaces.get(name, "")
            arm = BagRobot(self.writer, state.robot, ns)
            placed = in_cell or (not state.origin.isIdentity() and arm.tree.root != WORLD_FRAME)
            arm.start(0.0, xyz_xyzw(state.origin) if placed else None, WORLD_FRAME)
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
        self.part_frames = PartFrames(world.frame_s)
        if world.parts.parts.all():
            self.on_parts(world.parts.parts.all(), t0)
        self.cameras = CameraFeed(world, self._camera)  # each camera's reports (camera_feed)
        self.cameras.sync(True)

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
        try:
            arm.bag.frame(t_s, q, self._velocity(arm, t_s, at, q))
        except Exception as exc:
            self._broken(exc)
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
        out.append(marker_message(t_s, arm.marker_frame, arm.next_id, marker))
        arm.live.append(arm.next_id)
        arm.next_id = (arm.next_id + 1) % INT32  # ids are int32; the live ones stay apart
        self._markers(t_s, out, arm)

    def on_clear_markers(self, robot: str) -> None:
        arm = self.arms.get(robot)
        if arm is None or self.closed or not arm.live:
            return
        t_s = self._t()
        gone = [mk.delete_marker(t_s, arm.marker_frame, "markers", k) for k in arm.live]
        arm.live.clear()
        self._markers(t_s, gone, arm)

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        arm = self.arms.get(robot)
        if arm is None or self.closed:
            return
        t_s = self._t()
        now = {obj.name: obj for obj in objects}
        out = [
            mk.delete_marker(t_s, arm.object_frame, "workcell", arm.object_ids.pop(name))
            for name in arm.objects
            if name not in now
        ]
        for name, obj in now.items():
            if arm.objects.get(name) is not obj:
                if name not in arm.object_ids:
                    arm.object_ids[name] = arm.next_object
                    arm.next_object = (arm.next_object + 1) % INT32
                out.append(object_message(t_s, arm.object_frame, arm.object_ids[name], obj))
        arm.objects = now
        if out:
            self._markers(t_s, out, arm)

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        if self.closed or not self.arms:
            return
        frames, t_s = self.part_frames, max(0.0, t - self.t0)
        arm = next(iter(self.arms.values()))
        changes = frames.markers(t_s, parts)
        if not changes and not frames.due(t):
            frames.pending = list(parts)
            return
        frames.last_t, frames.pending = t, None
        to_parent = (
            pin.SE3.Identity() if arm.marker_frame == WORLD_FRAME else arm.state.origin.inverse()
        )
        try:
            self.writer.tf(t_s, part_transforms(t_s, arm.marker_frame, to_parent, parts))
        except Exception as exc:
            self._broken(exc)
        if changes:
            self._markers(t_s, changes, arm)

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        if not self.closed:
            self.cameras.sync(True)

    def _camera(self, name: str, t: float, seen: Sequence[Seen]) -> None:
        """What camera ``name`` saw at ``t``: its topic, and its frames on /tf."""
        if self.closed or not self.arms:
            return
        t_s = max(0.0, t - self.t0)
        arm = next(iter(self.arms.values()))
        to_parent = (
            pin.SE3.Identity() if arm.marker_frame == WORLD_FRAME else arm.state.origin.inverse()
        )
        camera = self.world.cameras.get(name)
        try:
            topic = CAMERA_TOPIC.format(name=name)
            self.writer.write(topic, POSE_ARRAY, t_s, pose_array(t_s, name, seen))
            items = camera_items(arm.marker_frame, to_parent, camera, seen)
            self.writer.tf(t_s, tf_message(transforms(t_s, items)))
        except Exception as exc:
            self._broken(exc)

    def _markers(self, t_s: float, markers: list[Msg], arm: _Arm) -> None:
        try:
            self.writer.markers(t_s, mk.marker_array(markers), arm.bag.namespace)
        except Exception as exc:
            self._broken(exc)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.cameras.wake()
        if accepted and not self.closed:
            self.commands.add(f"{source}: {line}")

    def on_reply(self, source: str, line: str, reply: str) -> None:
        if not self.closed:
            self.replies.add(f"{source}: {line} -> {reply}")

    # The end.

    def _broken(self, exc: Exception) -> None:
        """Something the writer refused (a bug, never the command's fault): the bag stops."""
        log.exception("bag %s: %s", self.path, exc, exc_info=exc)
        if not self.closed:  # no more writes; close() still ends the file
            self._failed(f"bag: {exc}")

    def _failed(self, error: str) -> None:
        self.error = self.error or error
        self.closed = True
        self.cameras.close()
        for lines in (self.commands, self.replies):
            if lines.timer is not None:
                lines.timer.cancel()
        self.on_failed(self, error)

    def stop(self) -> None:
        """Write what waits and take no more (on the asyncio thread); ``close`` ends the bag."""
        self.cameras.close()
        pending = self.part_frames.pending
        if pending is not None and not self.closed:
            self.part_frames.last_t = None
            self.on_parts(pending, self.world.clock.now())
        if not self.closed:
            self.commands.flush()
            self.replies.flush()
        self.closed = True

    def close(self) -> str | None:
        """Write the bag's summary and metadata (blocking: for a thread); return why it
        stopped early, if it did."""
        self.closed = True
        self.writer.close()
        return self.writer.error or self.error
