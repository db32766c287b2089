"""ROS 2 messages as plain dicts: the JSON shapes rosbridge sends, and what the bag writer takes;
markers among them.

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
and workcell objects are below.

``visualization_msgs`` markers as plain dicts: c2rviz's markers and workcell objects.
Every builder returns a complete Humble ``Marker`` (every field present), for rosbridge's
JSON and for ``BagWriter`` alike. A marker is named by its namespace and id (``ns``,
``id``); ``ADD`` adds or replaces it, ``DELETE`` removes it, ``DELETEALL`` removes every
marker of a namespace (of all namespaces when ``ns`` is empty). Positions [m] in the
marker's frame, orientations as unit quaternions (x, y, z, w), colours 0..1.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from typing import Any

from .errors import MessageError

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


MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"

# visualization_msgs/msg/Marker types and actions.
ARROW, CUBE, SPHERE, CYLINDER, MESH_RESOURCE = 0, 1, 2, 3, 10
ADD, DELETE, DELETEALL = 0, 2, 3
SHAPES: dict[str, int] = {
    "arrow": ARROW,
    "cube": CUBE,
    "box": CUBE,
    "sphere": SPHERE,
    "cylinder": CYLINDER,
    "mesh": MESH_RESOURCE,
}
"""Marker type of each c2rviz marker shape and workcell object shape."""


def _time_zero() -> Msg:
    return {"sec": 0, "nanosec": 0}


def marker(
    t_s: float,
    frame_id: str,
    ns: str,
    marker_id: int,
    shape: int,
    position: Sequence[float] = (0.0, 0.0, 0.0),
    quat_xyzw: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
    scale: Sequence[float] = (1.0, 1.0, 1.0),
    rgba: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
    action: int = ADD,
    mesh_resource: str = "",
) -> Msg:
    """``visualization_msgs/msg/Marker`` (Humble's fields, every one present).

    Args:
        t_s: Stamp [s].
        frame_id: The frame the pose is in.
        ns: Namespace; with ``marker_id`` it names the marker for later DELETE.
        marker_id: Id within ``ns`` (int32).
        shape: ``ARROW``, ``CUBE``, ``SPHERE``, ``CYLINDER`` or ``MESH_RESOURCE``.
        position: Centre x, y, z [m] in ``frame_id``.
        quat_xyzw: Orientation, unit quaternion x, y, z, w.
        scale: Size x, y, z [m] (a sphere's and cylinder's are diameters; an
            arrow's are its length, shaft and head diameters; a mesh's are scale factors).
        rgba: Colour, each channel 0..1.
        action: ``ADD`` (also modifies), ``DELETE`` or ``DELETEALL``.
        mesh_resource: ``MESH_RESOURCE``'s ``file://`` or ``package://`` URI.

    Raises:
        MessageError: an unknown shape or action, or an id outside int32.
    """
    if shape not in SHAPES.values():
        raise MessageError(f"marker: shape {shape} is not one of {sorted(set(SHAPES.values()))}")
    if action not in (ADD, DELETE, DELETEALL):
        raise MessageError(f"marker: action {action} is not ADD (0), DELETE (2) or DELETEALL (3)")
    if not -INT32 <= marker_id < INT32:
        raise MessageError(f"marker: id {marker_id} is outside int32")
    px, py, pz = position
    qx, qy, qz, qw = quat_xyzw
    sx, sy, sz = scale
    r, g, b, a = rgba
    return {
        "header": header(t_s, frame_id),
        "ns": ns,
        "id": int(marker_id),
        "type": shape,
        "action": action,
        "pose": {
            "position": {"x": float(px), "y": float(py), "z": float(pz)},
            "orientation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
        },
        "scale": {"x": float(sx), "y": float(sy), "z": float(sz)},
        "color": {"r": float(r), "g": float(g), "b": float(b), "a": float(a)},
        "lifetime": _time_zero(),  # forever
        "frame_locked": False,
        "points": [],
        "colors": [],
        "texture_resource": "",
        "texture": {"header": header(0.0), "format": "", "data": []},
        "uv_coordinates": [],
        "text": "",
        "mesh_resource": mesh_resource,
        "mesh_file": {"filename": "", "data": []},
        "mesh_use_embedded_materials": False,
    }


def delete_marker(t_s: float, frame_id: str, ns: str, marker_id: int) -> Msg:
    """A ``DELETE`` of marker ``ns``/``marker_id``."""
    return marker(t_s, frame_id, ns, marker_id, CUBE, action=DELETE)


def delete_all(t_s: float, frame_id: str = "", ns: str = "") -> Msg:
    """A ``DELETEALL``: every marker of ``ns`` (of every namespace when ``ns`` is empty)."""
    return marker(t_s, frame_id, ns, 0, CUBE, action=DELETEALL)


def object_marker(
    t_s: float,
    frame_id: str,
    ns: str,
    marker_id: int,
    shape: str,
    size: Sequence[float],
    position: Sequence[float],
    quat_xyzw: Sequence[float],
    rgba: Sequence[float],
    mesh_uri: str = "",
) -> Msg:
    """A workcell object as a marker, its size given as the URDF gives it.

    Args:
        t_s: Stamp [s].
        frame_id: The frame it is placed in (the robot's base link).
        ns: Namespace (for instance ``workcell/NAME``).
        marker_id: Id within ``ns``.
        shape: ``box`` (x, y, z edges [m]), ``sphere`` (radius [m]), ``cylinder``
            (radius, length [m], along its z) or ``mesh`` (scale x, y, z).
        size: As ``shape`` says.
        position: Centre (a mesh's origin) x, y, z [m] in ``frame_id``.
        quat_xyzw: Orientation, unit quaternion x, y, z, w.
        rgba: Colour, each channel 0..1.
        mesh_uri: A mesh's file, as a ``file://`` or ``package://`` URI.

    Raises:
        MessageError: an unknown shape, or a size of the wrong length.
    """
    lengths = {"box": 3, "sphere": 1, "cylinder": 2, "mesh": 3}
    if shape not in lengths:
        raise MessageError(f"object shape {shape!r} is not one of {', '.join(sorted(lengths))}")
    if len(size) != lengths[shape]:
        raise MessageError(f"a {shape}'s size takes {lengths[shape]} values, not {len(size)}")
    scale: Sequence[float]
    if shape == "sphere":
        scale = (2 * size[0],) * 3
    elif shape == "cylinder":
        scale = (2 * size[0], 2 * size[0], size[1])
    else:
        scale = tuple(size)
    return marker(
        t_s,
        frame_id,
        ns,
        marker_id,
        SHAPES[shape],
        position,
        quat_xyzw,
        scale,
        rgba,
        mesh_resource=mesh_uri if shape == "mesh" else "",
    )


def marker_array(markers: Sequence[Msg]) -> Msg:
    """``visualization_msgs/msg/MarkerArray`` holding ``markers``."""
    return {"markers": list(markers)}
