"""``visualization_msgs`` markers as plain dicts: c2rviz's markers and workcell objects.

Pure, as ``messages``: every builder returns a complete Humble ``Marker``
(every field present), for rosbridge's JSON and for ``BagWriter`` alike. A
marker is named by its namespace and id (``ns``, ``id``); ``ADD`` adds or
replaces it, ``DELETE`` removes it, ``DELETEALL`` removes every marker of a
namespace (of all namespaces when ``ns`` is empty). Positions [m] in the
marker's frame, orientations as unit quaternions (x, y, z, w), colours 0..1.
"""

from __future__ import annotations

from collections.abc import Sequence

from .errors import MessageError
from .messages import INT32, Msg, header

__all__ = [
    "ADD",
    "ARROW",
    "CUBE",
    "CYLINDER",
    "DELETE",
    "DELETEALL",
    "MARKER_ARRAY",
    "MESH_RESOURCE",
    "SHAPES",
    "SPHERE",
    "delete_all",
    "delete_marker",
    "marker",
    "marker_array",
    "object_marker",
]

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
