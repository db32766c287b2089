"""ROS 2 messages as plain dicts: the JSON shapes rosbridge sends, and what the bag writer takes.

Pure: no I/O, the standard library only. Every builder returns a complete
message of its ROS 2 Humble type (every field present), so the same dict can go
to a rosbridge client as JSON or to ``BagWriter``. Times are seconds [s] of the
caller's clock, lengths metres [m], angles radians [rad]; orientations are unit
quaternions in ROS order (x, y, z, w).

Several robots in one cell follow ROS's convention: each robot's topics live in
its namespace (``topic("left", "joint_states")`` is ``/left/joint_states``) and
its frames take the namespace as a prefix (``frame_prefix("left")`` is
``left/``, as robot_state_publisher's ``frame_prefix`` parameter), while
``/tf`` and ``/tf_static`` stay global so the cell is one TF tree. Markers
and workcell objects are in ``markers``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from typing import Any

from .errors import MessageError

__all__ = [
    "INT32",
    "JOINT_STATE",
    "STRING",
    "TF_MESSAGE",
    "Msg",
    "frame_prefix",
    "header",
    "joint_state",
    "nanoseconds",
    "stamp",
    "string",
    "tf_message",
    "topic",
    "transform",
    "transforms",
]

Msg = dict[str, Any]
"""A message as a plain dict (nested dicts and lists, as rosbridge's JSON)."""

JOINT_STATE = "sensor_msgs/msg/JointState"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
STRING = "std_msgs/msg/String"

_NAMESPACE = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
INT32 = 2**31
"""Bound of ROS's int32 fields (seconds of a stamp, a marker's id)."""


def nanoseconds(t_s: float) -> int:
    """``t_s`` [s] to the nearest nanosecond [ns], exact to the float's last digit.

    (``round(t_s * 1e9)`` would lose up to 128 ns on epoch times: the product
    passes 2**53.)

    Raises:
        MessageError: ``t_s`` is not finite or outside the int32 seconds of ROS time.
    """
    if not math.isfinite(t_s) or not -INT32 <= t_s < INT32:
        raise MessageError(f"time {t_s!r} s is not a ROS time (finite, within +-2**31 s)")
    sec = math.floor(t_s)
    return sec * 1_000_000_000 + round((t_s - sec) * 1e9)


def stamp(t_s: float) -> Msg:
    """``builtin_interfaces/msg/Time`` for ``t_s`` [s], to the nearest nanosecond.

    Raises:
        MessageError: ``t_s`` is not finite or outside the int32 seconds of ROS time.
    """
    sec, nanosec = divmod(nanoseconds(t_s), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def header(t_s: float, frame_id: str = "") -> Msg:
    """``std_msgs/msg/Header`` stamped ``t_s`` [s] in frame ``frame_id``."""
    return {"stamp": stamp(t_s), "frame_id": frame_id}


def frame_prefix(namespace: str) -> str:
    """The frame prefix of a robot namespace: ``left/``, or ``""`` for none.

    Raises:
        MessageError: not a ROS name (a letter, then letters, digits or ``_``).
    """
    if not namespace:
        return ""
    if not _NAMESPACE.fullmatch(namespace):
        raise MessageError(
            f"namespace {namespace!r} is not a ROS name (a letter, then letters, digits or '_')"
        )
    return namespace + "/"


def topic(namespace: str, name: str) -> str:
    """``/NAMESPACE/NAME``, or ``/NAME`` without a namespace (``name`` without slashes)."""
    return "/" + frame_prefix(namespace) + name


def joint_state(
    t_s: float,
    names: Sequence[str],
    positions: Sequence[float],
    velocities: Sequence[float] = (),
    efforts: Sequence[float] = (),
    frame_id: str = "",
) -> Msg:
    """``sensor_msgs/msg/JointState``: joints by name, positions [rad or m].

    Args:
        t_s: Stamp [s].
        names: Joint names.
        positions: One per name [rad or m].
        velocities: Empty, or one per name [rad/s or m/s].
        efforts: Empty, or one per name [N m or N].
        frame_id: Header frame (robot_state_publisher ignores it).

    Raises:
        MessageError: a list whose length is neither the names' nor (for
            velocities and efforts) zero.
    """
    n = len(names)
    for what, values, may_be_empty in (
        ("positions", positions, False),
        ("velocities", velocities, True),
        ("efforts", efforts, True),
    ):
        if len(values) != n and not (may_be_empty and len(values) == 0):
            raise MessageError(
                f"joint_state: {len(values)} {what} for {n} names "
                f"(give one per name{' or none' if may_be_empty else ''})"
            )
    return {
        "header": header(t_s, frame_id),
        "name": list(names),
        "position": [float(v) for v in positions],
        "velocity": [float(v) for v in velocities],
        "effort": [float(v) for v in efforts],
    }


def transform(
    t_s: float,
    parent: str,
    child: str,
    translation: Sequence[float],
    quat_xyzw: Sequence[float],
) -> Msg:
    """``geometry_msgs/msg/TransformStamped``: frame ``child`` in frame ``parent``.

    Args:
        t_s: Stamp [s].
        parent: The header's frame (the parent link).
        child: ``child_frame_id`` (the child link).
        translation: x, y, z [m] of the child's origin in the parent frame.
        quat_xyzw: The child's orientation in the parent frame, unit quaternion x, y, z, w.
    """
    x, y, z = translation
    qx, qy, qz, qw = quat_xyzw
    return {
        "header": header(t_s, parent),
        "child_frame_id": child,
        "transform": {
            "translation": {"x": float(x), "y": float(y), "z": float(z)},
            "rotation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
        },
    }


def transforms(
    t_s: float,
    items: Iterable[tuple[str, str, Sequence[float], Sequence[float]]],
) -> list[Msg]:
    """``transform`` for each (parent, child, translation, quat_xyzw), one stamp for all."""
    time = stamp(t_s)
    return [
        {
            "header": {"stamp": time, "frame_id": parent},
            "child_frame_id": child,
            "transform": {
                "translation": {"x": float(x), "y": float(y), "z": float(z)},
                "rotation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
            },
        }
        for parent, child, (x, y, z), (qx, qy, qz, qw) in items
    ]


def tf_message(transforms: Sequence[Msg]) -> Msg:
    """``tf2_msgs/msg/TFMessage`` holding ``transforms`` (from ``transform``)."""
    return {"transforms": list(transforms)}


def string(text: str) -> Msg:
    """``std_msgs/msg/String``."""
    return {"data": text}
