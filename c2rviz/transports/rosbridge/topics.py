"""The topics rosbridge serves of each robot and camera, and the robots' diagnostics.

One robot's topics: their names, its frames, its messages. The messages are those of
``c2rviz.ros`` (the bag writer's shapes): a robot alone lives in the root namespace
(``/joint_states``, frames ``base_link``...); in a cell each robot lives in its own
(``/left/joint_states``, frames ``left/base_link``), ``/tf`` and ``/tf_static`` stay
global, and the cell's ``world`` frame holds every robot's root where the cell places
it. A marker of the world (``world.state.Marker``) is drawn in the world frame: the
cell's ``world``, or a robot alone's root link. Workcell objects are placed in the
robot's base link. Sizes follow the page's (``MARKER_SIZE_M``).

The logical cameras: each camera NAME publishes ``/c2rviz/cameras/NAME``
(``geometry_msgs/msg/PoseArray``): its header's ``frame_id`` is the camera's frame
``cameras/NAME`` and its poses are the seen parts' in that frame, in the order ``camera
NAME`` replies them (an empty array: it sees nothing). A PoseArray is in rosbags' ROS 2
stores and RViz draws it; it carries no names, so the same report goes on ``/tf`` too:
the camera's frame (a child of the world's frame, as the parts' frames are) and a frame
``cameras/NAME/PART`` per seen part, a child of the camera's, so a TF listener knows
which part is where. Reports come at the camera's rate on the world's clock
(``observers.camera_feed``), while anyone subscribes to a camera's topic; a new
subscriber gets what the camera sees now at once. A camera's topic exists from the
moment the camera is placed (topics are never taken back: a removed camera's topic
publishes nothing more).

The robots' faults as ROS diagnostics (pure): ``/diagnostics``
(``diagnostic_msgs/msg/DiagnosticArray``), the ROS convention for a machine's health.
One ``DiagnosticStatus`` per robot, named ``c2rviz/ROBOT`` with ``hardware_id`` ROBOT:

* level ``ERROR`` (2) while a stop holds the robot (``estop``, ``protective``, a released
  estop not yet ``reset``) or a joint is stalled; ``WARN`` (1) with only noise or latency;
  ``OK`` (0) without faults;
* ``message``: the stop's refusal (``emergency stop since t=...``), else the faults, else
  ``ok``;
* ``values``: one ``{key, value}`` per fault, active or scheduled (``estop`` ->
  ``since 1.500``, ``noise 0.01`` -> ``at 5.000``), as ``faults`` lists them (SI).

The level is sent as a JSON number (what roslibpy clients read; rosbridge_suite's own
encoding of a ``byte`` varies with its version).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from functools import partial

import numpy as np
import pinocchio as pin

from ...collision.workcell import WorkcellObject
from ...observers.camera_feed import CAMERA_TOPIC, POSE_ARRAY, CameraFeed, camera_items, pose_array
from ...robot.model import Robot
from ...ros.messages import (
    JOINT_STATE,
    SHAPES,
    Msg,
    delete_all,
    delete_marker,
    frame_prefix,
    header,
    joint_state,
    marker,
    object_marker,
    tf_message,
    topic,
    transform,
    transforms,
)
from ...ros.tf_tree import TfTree, Transform
from ...world.cameras import Camera, Seen
from ...world.faults import RobotFaults
from ...world.observer import Observer
from ...world.state import Marker
from ...world.world import World, sight
from .bridge import TopicHub
from .messages import JOINT_TRAJECTORY, STRING

# One robot's topics.

TF_MESSAGE = "tf2_msgs/msg/TFMessage"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
WORLD_FRAME = "world"
"""The cell's frame: each robot's root link hangs from it on ``/tf_static``."""
MARKER_SIZE_M = 0.03
"""A marker's size [m], as the page draws it (``view.markers.MARKER_SIZE_M``)."""
_NOT_NAME = re.compile(r"[^A-Za-z0-9_]")


def namespaces(names: Sequence[str], cell: bool) -> dict[str, str]:
    """Each robot's ROS namespace: ``""`` for a robot alone, else its name made a ROS name.

    Characters a ROS name cannot hold become ``_``, a name that does not start
    with a letter gets ``r`` before it, and a name taken twice gets ``_2``, ``_3``...
    """
    if not cell:
        return dict.fromkeys(names, "")
    out: dict[str, str] = {}
    for name in names:
        base = _NOT_NAME.sub("_", name)
        base = base if base[:1].isalpha() else "r" + base
        chosen, k = base, 2
        while chosen in out.values():
            chosen, k = f"{base}_{k}", k + 1
        out[name] = chosen
    return out


def _xyzw(wxyz: Sequence[float]) -> tuple[float, float, float, float]:
    w, x, y, z = wxyz
    return (x, y, z, w)


def _marker_scale(shape: str) -> tuple[float, float, float]:
    s = MARKER_SIZE_M
    if shape == "arrow":
        return (1.7 * s, s / 4, s / 4)
    if shape == "cylinder":
        return (2 * s / 3, 2 * s / 3, s)
    return (s, s, s)


class RobotTopics:
    """The topic names, frames and messages of one robot of the world.

    Attributes:
        name: The robot's name in the world.
        namespace: Its ROS namespace (``""`` alone).
        robot: Its model.
        tree: Its TF (frames prefixed with the namespace).
        marker_frame: Where markers are drawn (``world`` in a cell, else the root link).
        object_frame: Where workcell objects are placed (its base link).
        joint_states, robot_description, events, markers, reply, command,
        joint_command, joint_trajectory: Its topics' absolute names.
    """

    def __init__(self, name: str, robot: Robot, namespace: str, cell: bool) -> None:
        """Name the robot's topics and read its TF.

        Raises:
            DescriptionError: The robot's URDF joint tree cannot be read.
        """
        self.name, self.robot, self.namespace, self.cell = name, robot, namespace, cell
        prefix = frame_prefix(namespace)
        self.tree = TfTree(robot, prefix)
        self.marker_frame = WORLD_FRAME if cell else self.tree.root
        self.object_frame = prefix + robot.base
        self.joint_states = topic(namespace, "joint_states")
        self.robot_description = topic(namespace, "robot_description")
        self.events = topic(namespace, "c2rviz/events")
        self.markers = topic(namespace, "visualization_marker_array")
        self.reply = topic(namespace, "c2rviz/reply")
        self.command = topic(namespace, "c2rviz/command")
        self.joint_command = topic(namespace, "joint_command")
        self.joint_trajectory = topic(namespace, "joint_trajectory")
        self.markers_ns = prefix + "markers"
        self.objects_ns = prefix + "workcell"
        self._moving: tuple[tuple[float, ...], list[Transform]] | None = None

    def published(self) -> list[tuple[str, str]]:
        """``(topic, type)`` of what c2rviz publishes for this robot."""
        return [
            (self.joint_states, JOINT_STATE),
            (self.robot_description, STRING),
            (self.events, STRING),
            (self.markers, MARKER_ARRAY),
            (self.reply, STRING),
        ]

    def taken(self) -> list[tuple[str, str]]:
        """``(topic, type)`` of what c2rviz takes for this robot."""
        return [
            (self.command, STRING),
            (self.joint_command, JOINT_STATE),
            (self.joint_trajectory, JOINT_TRAJECTORY),
        ]

    def joint_state(self, q: Sequence[float], t: float) -> Msg:
        """``/joint_states`` for chain values ``q`` [rad or m] at time ``t`` [s]: every
        moving joint of the URDF, mimic and off-chain joints included."""
        names, positions = self.tree.joint_positions(self.robot.configuration(q))
        return joint_state(t, names, positions)

    def moving(self, q: tuple[float, ...]) -> list[Transform]:
        """The moving joints' transforms at ``q`` (the last one asked is kept)."""
        if self._moving is None or self._moving[0] != q:
            self._moving = (q, self.tree.moving_transforms(self.robot.configuration(q)))
        return self._moving[1]

    def statics(self, t: float, origin: pin.SE3) -> list[Msg]:
        """The fixed joints' transforms, and in a cell the root link in ``world``."""
        out = [transform(t, *item) for item in self.tree.static_transforms()]
        if self.cell:
            x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(origin).tolist()
            out.append(transform(t, WORLD_FRAME, self.tree.root, (x, y, z), (qx, qy, qz, qw)))
        return out

    def marker(self, t: float, marker_id: int, item: Marker) -> Msg:
        """One of the robot's markers (ADD), in ``marker_frame``."""
        r, g, b = item.rgb
        return marker(
            t,
            self.marker_frame,
            self.markers_ns,
            marker_id,
            SHAPES[item.shape],
            item.position,
            _xyzw(item.wxyz),
            _marker_scale(item.shape),
            (r, g, b, 1.0),
        )

    def marker_gone(self, t: float, marker_id: int) -> Msg:
        """A DELETE of one marker (pushed out past ``MAX_MARKERS``)."""
        return delete_marker(t, self.marker_frame, self.markers_ns, marker_id)

    def markers_cleared(self, t: float) -> Msg:
        """A DELETEALL of the robot's markers."""
        return delete_all(t, self.marker_frame, self.markers_ns)

    def objects(self, t: float, objects: Iterable[WorkcellObject]) -> list[Msg]:
        """The workcell as markers: a DELETEALL of the old ones, then each object."""
        out = [delete_all(t, self.object_frame, self.objects_ns)]
        for k, obj in enumerate(objects):
            x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(obj.placement).tolist()
            mesh = obj.mesh_path.resolve().as_uri() if obj.mesh_path is not None else ""
            out.append(
                object_marker(
                    t,
                    self.object_frame,
                    self.objects_ns,
                    k,
                    obj.shape,
                    obj.size,
                    (x, y, z),
                    (qx, qy, qz, qw),
                    tuple(np.clip(obj.rgba, 0.0, 1.0).tolist()),
                    mesh,
                )
            )
        return out


# The cameras' topics.


class CameraTopics(Observer):
    """Publishes every camera of the world (add it to the world's observers)."""

    def __init__(
        self, world: World, hub: TopicHub, parent: str, to_parent: pin.SE3, tf_topic: str
    ) -> None:
        """Set up.

        Args:
            world: The world whose cameras it publishes.
            hub: Where the messages go.
            parent: The frame cameras hang from on ``/tf`` (the parts' parent).
            to_parent: Takes a world pose into ``parent``.
            tf_topic: ``/tf``.
        """
        self.world, self.hub = world, hub
        self.parent, self.to_parent, self.tf_topic = parent, to_parent, tf_topic
        self.topics: dict[str, str] = {}
        self._readers = 0
        self.feed = CameraFeed(world, self._report)
        self.on_cameras(world.cameras.all())

    def published(self) -> list[tuple[str, str]]:
        """``(topic, type)`` of every camera's topic."""
        return [(topic, POSE_ARRAY) for topic in self.topics.values()]

    def close(self) -> None:
        self.feed.close()

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        for camera in cameras:
            if camera.name not in self.topics:
                topic = self.topics[camera.name] = CAMERA_TOPIC.format(name=camera.name)
                self.hub.add_topic(topic, partial(self._now, camera.name), watcher=self._reading)
        self.feed.sync(self._readers > 0)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.feed.wake()

    def _reading(self, reading: bool) -> None:
        self._readers += 1 if reading else -1
        self.feed.sync(self._readers > 0)

    def _now(self, name: str) -> Msg | None:
        if name not in self.world.cameras:
            return None
        return pose_array(self.world.clock.now(), name, sight(self.world, name))

    def _report(self, name: str, t: float, seen: Sequence[Seen]) -> None:
        topic = self.topics.get(name)
        if topic is not None and self.hub.wanted(topic):
            self.hub.publish(topic, pose_array(t, name, seen))
        if self.hub.wanted(self.tf_topic):
            camera = self.world.cameras.get(name)
            items = camera_items(self.parent, self.to_parent, camera, seen)
            self.hub.publish(self.tf_topic, tf_message(transforms(t, items)))


# The robots' diagnostics.

DIAGNOSTICS_TOPIC = "/diagnostics"
DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"
OK, WARN, ERROR = 0, 1, 2


def status(robot: str, faults: RobotFaults, origin: float) -> Msg:
    """``robot``'s ``DiagnosticStatus`` (times from ``origin`` [s])."""
    listed = faults.listing(origin)
    texts = [fault.text(faults.joint_names) for fault, _ in listed]
    refusal = faults.refusal(origin)
    if refusal is not None or faults.held:
        level = ERROR
    elif faults.active:
        level = WARN
    else:
        level = OK
    if refusal is not None:
        message = str(refusal)
    else:
        active = [fault.text(faults.joint_names) for fault, _ in faults.active.values()]
        message = "faults: " + ", ".join(active) if active else "ok"
    return {
        "level": level,
        "name": f"c2rviz/{robot}",
        "message": message,
        "hardware_id": robot,
        "values": [{"key": text, "value": when} for text, (_, when) in zip(texts, listed)],
    }


def diagnostics(t: float, robots: Mapping[str, RobotFaults], origin: float) -> Msg:
    """``/diagnostics`` at time ``t`` [s]: every robot's status."""
    return {
        "header": header(t),
        "status": [status(name, faults, origin) for name, faults in robots.items()],
    }
