"""One robot's topics as rosbridge serves them: their names, its frames, its messages.

The messages are those of ``c2rviz.ros`` (the bag writer's shapes): a robot
alone lives in the root namespace (``/joint_states``, frames ``base_link``...);
in a cell each robot lives in its own (``/left/joint_states``, frames
``left/base_link``), ``/tf`` and ``/tf_static`` stay global, and the cell's
``world`` frame holds every robot's root where the cell places it.

A marker of the world (``world.state.Marker``) is drawn in the world frame: the
cell's ``world``, or a robot alone's root link. Workcell objects are placed in
the robot's base link. Sizes follow the page's (``MARKER_SIZE_M``).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

import numpy as np
import pinocchio as pin

from ...collision.workcell import WorkcellObject
from ...robot.model import Robot
from ...ros.messages import (
    JOINT_STATE,
    SHAPES,
    Msg,
    delete_all,
    delete_marker,
    frame_prefix,
    joint_state,
    marker,
    object_marker,
    topic,
    transform,
)
from ...ros.tf_tree import TfTree, Transform
from ...world.state import Marker
from .messages import JOINT_TRAJECTORY, STRING

__all__ = [
    "MARKER_ARRAY",
    "MARKER_SIZE_M",
    "TF_MESSAGE",
    "WORLD_FRAME",
    "RobotTopics",
    "namespaces",
]

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
