"""Writing a rosbag2 bag (MCAP storage) that ROS tools open, without ROS.

``BagWriter(path)`` makes the folder ``path/`` with ``metadata.yaml`` and one
``NAME.mcap`` (MCAP profile ``ros2``, ``ros2msg`` schemas, CDR messages, rosbag2
metadata version 9, ROS 2 Humble types) through ``rosbags.rosbag2.Writer``. It
takes the dict messages of ``messages``, stamped in seconds [s] of the
recording clock, and encodes them with ``CdrEncoder`` (compiled once per type,
no message objects). A topic's connection is made on its first message;
``/tf_static`` and every ``robot_description`` topic are offered with
transient-local QoS (depth 1), as robot_state_publisher offers them, so a late
subscriber of ``ros2 bag play`` still gets them. ``/tf_static`` collects:
each message on it repeats every static transform written so far, as tf2's
static broadcaster does.

A write error (a full disk: ENOSPC, a file-size limit: EFBIG, any OSError)
stops the bag: the error is logged and reported once (``error``, and
``on_error`` if given), later writes are ignored, and the bag is ended where
it stands. The end state after an error:

- ``NAME.mcap`` holds every message up to its last whole chunk (rosbags writes
  chunks of about 1 MiB: the newest messages up to that size are lost), ended
  with MCAP's DataEnd and Footer records and no summary. ``rosbags`` and the
  ``mcap`` package read it by scanning; ``ros2 bag play`` wants it indexed
  first (``mcap recover``).
- ``metadata.yaml`` is written from what ``NAME.mcap`` really holds.
- Room for both is kept: a reserve file ``.c2rviz-reserve`` of
  ``RESERVE_BYTES`` sits in the folder while recording and is deleted before the
  bag is ended (and before a normal close writes its summary). Should the disk
  still refuse those few hundred bytes, the warning says the bag "could not be
  fully ended" and ``bag_repair.end_bag`` can end it later.

Ending a bag after an error reads it through once (about 1 s per 300 MB here),
on the caller's thread; a caller on an event loop may want ``close`` and the
writes that can fail in a worker thread, or to accept that one pause.

``BagRobot``: one robot's topics in a bag, as robot_state_publisher and
joint_state_publisher give them. ``BagRobot(writer, robot, namespace)`` writes, for a
robot of a recording: ``[/NS]/robot_description`` and its fixed joints on ``/tf_static``
once (``start``), then with each frame (``frame``) its ``[/NS]/joint_states`` (every
moving joint of the URDF) and its moving joints' transforms on ``/tf``, both stamped with
the frame's time [s]. In a cell each robot has a namespace; its frames are prefixed with
it (``left/base_link``) and ``start`` can place its root link in the cell's ``world``
frame.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from rosbags.interfaces import (
    Connection,
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import StoragePlugin, Writer, WriterError
from rosbags.typesys import Stores, get_typestore

from ..robot import Robot
from . import messages
from .bag_repair import end_bag
from .cdr import CdrEncoder
from .errors import BagError, MessageError
from .messages import (
    JOINT_STATE,
    MARKER_ARRAY,
    frame_prefix,
    joint_state,
    tf_message,
    topic,
    transform,
    transforms,
)
from .tf_tree import TfTree

log = logging.getLogger("c2rviz.ros.bag")

RESERVE_BYTES = 1 << 20
"""Disk space [bytes] held back while recording, to end the bag after a full disk."""
_RESERVE = ".c2rviz-reserve"
_UNSPECIFIED = QosTime(0, 0)  # rmw's "unspecified": the default (infinite) duration


def _qos(depth: int, durability: QosDurability) -> Qos:
    return Qos(
        QosHistory.KEEP_LAST,
        depth,
        QosReliability.RELIABLE,
        durability,
        _UNSPECIFIED,
        _UNSPECIFIED,
        QosLiveliness.AUTOMATIC,
        _UNSPECIFIED,
        False,
    )


QOS_LATCHED = _qos(1, QosDurability.TRANSIENT_LOCAL)
"""``/tf_static`` and ``robot_description``: reliable, transient local, depth 1."""
QOS_TF = _qos(100, QosDurability.VOLATILE)
"""``/tf``: reliable, volatile, depth 100 (tf2's broadcaster)."""
QOS_DEFAULT = _qos(10, QosDurability.VOLATILE)
"""Every other topic: reliable, volatile, depth 10."""


def qos_for(topic: str) -> Qos:
    """The QoS a topic is offered with in the bag."""
    if topic == "/tf_static" or topic.endswith("/robot_description"):
        return QOS_LATCHED
    return QOS_TF if topic == "/tf" else QOS_DEFAULT


class BagWriter:
    """One rosbag2 bag being written; every method is cheap and never raises an OSError."""

    def __init__(
        self,
        path: str | Path,
        *,
        on_error: Callable[[str], None] | None = None,
        reserve_bytes: int = RESERVE_BYTES,
    ) -> None:
        """Create the folder ``path`` and open its ``.mcap``.

        Args:
            path: The bag folder to create (its name names the ``.mcap``).
            on_error: Called once with the message when a write error stops the bag.
            reserve_bytes: Disk space held back to end the bag after a full disk.

        Raises:
            BagError: ``path`` exists, or cannot be created.
        """
        self.path = Path(path)
        self.mcap = self.path / f"{self.path.name}.mcap"
        self.on_error = on_error
        self.error: str | None = None
        """Why writing stopped early, if it did."""
        self.closed = False
        self.messages = 0
        """Messages handed to the writer (some may be lost to a write error)."""
        self.typestore = get_typestore(Stores.ROS2_HUMBLE)
        self.encoder = CdrEncoder(self.typestore)
        self._connections: dict[str, tuple[Connection, str]] = {}
        self._static: dict[str, messages.Msg] = {}  # /tf_static so far, by child frame
        try:
            self._writer = Writer(self.path, version=9, storage_plugin=StoragePlugin.MCAP)
            self._writer.open()
        except WriterError:
            raise BagError(str(self.path), "exists already; give a new name") from None
        except OSError as exc:
            raise BagError(str(self.path), f"cannot be created: {exc.strerror or exc}") from None
        self._reserve = self.path / _RESERVE
        try:
            with open(self._reserve, "wb") as file:
                if reserve_bytes > 0:
                    os.posix_fallocate(file.fileno(), 0, reserve_bytes)
        except OSError as exc:
            self._fail(exc)

    # Writing.

    def write(self, topic: str, msgtype: str, t_s: float, message: Mapping[str, Any]) -> None:
        """Write one message (a dict of ``msgtype``) on ``topic``, logged at ``t_s`` [s].

        Raises:
            MessageError: the message does not fit its type, the topic already has
                another type, or ``t_s`` is negative (bag times are unsigned).
        """
        if self.closed:
            return
        data = memoryview(self.encoder.encode(msgtype, message))  # first: it checks the type
        if t_s < 0:
            raise MessageError(f"bag time {t_s} s is negative")
        log_ns = messages.nanoseconds(t_s)  # the header stamps' own rounding
        known = self._connections.get(topic)
        if known is None or known[1] != msgtype:
            known = self._connect(topic, msgtype)
        try:
            self._writer.write(known[0], log_ns, data)
        except OSError as exc:
            self._fail(exc)
            return
        self.messages += 1

    def _connect(self, topic: str, msgtype: str) -> tuple[Connection, str]:
        if topic in self._connections:
            raise MessageError(
                f"topic {topic} carries {self._connections[topic][1]}, not {msgtype}"
            )
        connection = self._writer.add_connection(
            topic, msgtype, typestore=self.typestore, offered_qos_profiles=[qos_for(topic)]
        )
        self._connections[topic] = (connection, msgtype)
        return self._connections[topic]

    def joint_state(self, t_s: float, message: Mapping[str, Any], namespace: str = "") -> None:
        """A ``sensor_msgs/msg/JointState`` on ``[/NAMESPACE]/joint_states``."""
        self.write(messages.topic(namespace, "joint_states"), messages.JOINT_STATE, t_s, message)

    def tf(self, t_s: float, message: Mapping[str, Any]) -> None:
        """A ``tf2_msgs/msg/TFMessage`` on ``/tf``."""
        self.write("/tf", messages.TF_MESSAGE, t_s, message)

    def tf_static(self, t_s: float, transforms: Sequence[Mapping[str, Any]]) -> None:
        """Add static transforms; ``/tf_static`` gets every one written so far."""
        for item in transforms:
            self._static[item["child_frame_id"]] = dict(item)
        everything = messages.tf_message(list(self._static.values()))
        self.write("/tf_static", messages.TF_MESSAGE, t_s, everything)

    def robot_description(self, t_s: float, urdf: str, namespace: str = "") -> None:
        """The URDF text on ``[/NAMESPACE]/robot_description``."""
        topic = messages.topic(namespace, "robot_description")
        self.write(topic, messages.STRING, t_s, messages.string(urdf))

    def text(self, topic: str, t_s: float, text: str) -> None:
        """A ``std_msgs/msg/String`` (for ``/c2rviz/commands`` and ``/c2rviz/replies``)."""
        self.write(topic, messages.STRING, t_s, messages.string(text))

    def markers(self, t_s: float, message: Mapping[str, Any], namespace: str = "") -> None:
        """A ``MarkerArray`` on ``[/NAMESPACE]/visualization_marker_array``."""
        topic = messages.topic(namespace, "visualization_marker_array")
        self.write(topic, MARKER_ARRAY, t_s, message)

    # The end.

    def close(self) -> None:
        """Write the summary and ``metadata.yaml`` (after an error: see the module)."""
        if self.closed:
            return
        self.closed = True
        self._unreserve()
        try:
            self._writer.close()
        except OSError as exc:
            self._fail(exc)

    def _unreserve(self) -> None:
        with contextlib.suppress(OSError):
            self._reserve.unlink(missing_ok=True)

    def _fail(self, exc: OSError) -> None:
        """A write failed: stop, end the bag where it stands, report once."""
        if self.error is not None:
            return
        self.closed = True
        self.error = f"write error: {exc.strerror or exc}"
        with contextlib.suppress(Exception):
            self._writer.abort()
        self._unreserve()
        ended = "ended"
        try:
            end_bag(self.path, self.typestore)
        except Exception as again:  # what is left is reported, whatever the reader said
            ended = f"could not be fully ended ({again})"
        log.warning("bag %s stopped by a %s; it is %s", self.path, self.error, ended)
        if self.on_error is not None:
            self.on_error(self.error)

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class BagRobot:
    """The TF and joint states of one robot, written to a ``BagWriter``."""

    def __init__(self, writer: BagWriter, robot: Robot, namespace: str = "") -> None:
        """Prepare the robot's topics (``namespace`` ``""`` for a robot alone).

        Raises:
            MessageError: ``namespace`` is not a ROS name.
            DescriptionError: the robot's URDF joint tree cannot be read.
        """
        self.writer = writer
        self.robot = robot
        self.namespace = namespace
        self.tree = TfTree(robot, frame_prefix(namespace))
        self.topic = topic(namespace, "joint_states")

    def start(
        self,
        t_s: float,
        root_in_world: tuple[Sequence[float], Sequence[float]] | None = None,
        world_frame: str = "world",
    ) -> None:
        """Write the URDF and the fixed joints (and the robot's place in the cell).

        Args:
            t_s: Stamp [s].
            root_in_world: Translation [m] and rotation (x, y, z, w) of the URDF's
                root link in ``world_frame``, or None to leave the robot unplaced.
            world_frame: The cell's frame.
        """
        self.writer.robot_description(t_s, self.robot.source.xml, self.namespace)
        statics = [transform(t_s, *item) for item in self.tree.static_transforms()]
        if root_in_world is not None:
            statics.append(transform(t_s, world_frame, self.tree.root, *root_in_world))
        self.writer.tf_static(t_s, statics)

    def frame(self, t_s: float, chain_q: Sequence[float], chain_v: Sequence[float] = ()) -> None:
        """Write the state at ``t_s`` [s]: joint states and the moving joints' transforms.

        Args:
            t_s: Stamp [s].
            chain_q: The chain's values [rad or m], as ``Robot.configuration`` takes them.
            chain_v: The chain's velocities [rad/s or m/s] while moving, or empty.
        """
        full_q = self.robot.configuration(chain_q)
        names, positions = self.tree.joint_positions(full_q)
        velocities = self.tree.joint_velocities(chain_v) if len(chain_v) else ()
        state = joint_state(t_s, names, positions, velocities)
        self.writer.write(self.topic, JOINT_STATE, t_s, state)
        moving = self.tree.moving_transforms(full_q)
        self.writer.tf(t_s, tf_message(transforms(t_s, moving)))
