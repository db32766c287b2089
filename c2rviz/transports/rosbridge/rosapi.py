"""The ``/rosapi/*`` services ROS clients call to look around, answered from a table (pure).

roslibpy's ``Ros.get_topics()``, ``get_topic_type()``, ``get_services()``,
``get_nodes()`` and ``Param.get()``, roslibjs's URDF loaders, and Foxglove's
and Lichtblick's Rosbridge connection (``/rosapi/topics_and_raw_types``) call
these. rosbridge answers them from the ROS graph; c2rviz answers them from a
``Graph`` its caller builds: the topics and services it has, its node and its
parameters. Answers follow ``rosapi_msgs/srv/*`` (ROS 2 rosapi): a topic or
service that does not exist has type ``""``; a parameter's value is JSON text.

The ROS 2 message definitions (``.msg`` text) of the types c2rviz publishes and takes:
``full_text`` gives a type's definition followed by those of every type it uses, in the
layout ``/rosapi/topics_and_raw_types`` sends (and ``gendeps --cat`` and rosbag2's MCAP
schemas use): the root's text, then for each dependency a line of 80 ``=``, a line
``MSG: package/Name`` and its text. The fields are those of ROS 2 Humble's interfaces
(comments left out). Foxglove and Lichtblick read this text to decode a topic's messages.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ...errors import C2rvizError
from .messages import TypeNameError, normalize_type
from .ops import resolve_name

# The .msg texts.

_SEPARATOR = "=" * 80
_XYZ = "float64 x\nfloat64 y\nfloat64 z\n"
_STAMP = "int32 sec\nuint32 nanosec\n"

DEFINITIONS: dict[str, str] = {
    "builtin_interfaces/Time": _STAMP,
    "builtin_interfaces/Duration": _STAMP,
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "std_msgs/String": "string data\n",
    "std_msgs/ColorRGBA": "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    "geometry_msgs/Vector3": _XYZ,
    "geometry_msgs/Point": _XYZ,
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    "geometry_msgs/PoseArray": "std_msgs/Header header\ngeometry_msgs/Pose[] poses\n",
    "geometry_msgs/Transform": (
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"
    ),
    "geometry_msgs/TransformStamped": (
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"
    ),
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms\n",
    "sensor_msgs/JointState": (
        "std_msgs/Header header\n\n"
        "string[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n"
    ),
    "sensor_msgs/CompressedImage": "std_msgs/Header header\nstring format\nuint8[] data\n",
    "trajectory_msgs/JointTrajectoryPoint": (
        "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\n"
        "float64[] effort\nbuiltin_interfaces/Duration time_from_start\n"
    ),
    "trajectory_msgs/JointTrajectory": (
        "std_msgs/Header header\nstring[] joint_names\n"
        "trajectory_msgs/JointTrajectoryPoint[] points\n"
    ),
    "visualization_msgs/UVCoordinate": "float32 u\nfloat32 v\n",
    "visualization_msgs/MeshFile": "string filename\nuint8[] data\n",
    "visualization_msgs/Marker": (
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\n"
        "int32 LINE_STRIP=4\nint32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\n"
        "int32 POINTS=8\nint32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\n"
        "int32 TRIANGLE_LIST=11\n\n"
        "int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\n"
        "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
        "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\n"
        "geometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\n"
        "string texture_resource\nsensor_msgs/CompressedImage texture\n"
        "visualization_msgs/UVCoordinate[] uv_coordinates\n"
        "string text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\n"
        "bool mesh_use_embedded_materials\n"
    ),
    "visualization_msgs/MarkerArray": "visualization_msgs/Marker[] markers\n",
    "diagnostic_msgs/KeyValue": "string key\nstring value\n",
    "diagnostic_msgs/DiagnosticStatus": (
        "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\n\n"
        "byte level\nstring name\nstring message\nstring hardware_id\n"
        "diagnostic_msgs/KeyValue[] values\n"
    ),
    "diagnostic_msgs/DiagnosticArray": (
        "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status\n"
    ),
}
"""Each type's ``.msg`` text, by ``package/Name``."""


def _short(type_name: str) -> str:
    package, _, name = normalize_type(type_name).split("/")
    return f"{package}/{name}"


def dependencies(type_name: str) -> list[str]:
    """The types (``package/Name``) the fields of ``type_name`` use, in field order."""
    found: list[str] = []
    for line in DEFINITIONS[_short(type_name)].splitlines():
        words = line.split("#", 1)[0].split()
        if len(words) < 2 or "=" in line:
            continue  # a blank line, a comment or a constant
        field_type = words[0].split("[", 1)[0].split("<=", 1)[0]
        if "/" in field_type and field_type not in found:
            found.append(field_type)
    return found


def full_text(type_name: str) -> str:
    """The definition of ``type_name`` and of all it uses, as rosapi sends it.

    Args:
        type_name: A message type in either spelling.

    Returns:
        The text, or "" for a type this module does not hold (rosapi's answer
        for a type it cannot find is an error; ours keeps the lists aligned).
    """
    try:
        root = _short(type_name)
    except TypeNameError:
        return ""
    if root not in DEFINITIONS:
        return ""
    text, seen, stack = DEFINITIONS[root], set(), dependencies(root)
    seen.update(stack)
    while stack:  # the order rosapi's stringify_field_types gives: a stack, not a queue
        current = stack.pop()
        text += f"\n{_SEPARATOR}\nMSG: {current}\n{DEFINITIONS[current]}"
        for used in dependencies(current):
            if used not in seen:
                seen.add(used)
                stack.append(used)
    return text


# The /rosapi/* services.


class RosapiError(C2rvizError):
    """A rosapi call c2rviz cannot answer (an unknown parameter, a mistyped field)."""


@dataclass(frozen=True)
class Graph:
    """What c2rviz shows of itself as a ROS graph.

    Attributes:
        topics: ``(name, type)`` of every topic, absolute names, ``pkg/msg/Name`` types.
        services: ``(name, type)`` of the services besides rosapi's own.
        nodes: The node names (``/c2rviz``).
        params: Parameter values by name (``robot_description``: the URDF text).
    """

    topics: tuple[tuple[str, str], ...] = ()
    services: tuple[tuple[str, str], ...] = ()
    nodes: tuple[str, ...] = ("/c2rviz",)
    params: Mapping[str, object] = field(default_factory=dict)


def _text(args: Mapping[str, Any], name: str, service: str) -> str:
    value = args.get(name, "")
    if not isinstance(value, str):
        raise RosapiError(f"{service}: {name} must be a string")
    return value


def _topics(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"topics": [t for t, _ in graph.topics], "types": [k for _, k in graph.topics]}


def _topics_and_raw_types(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    answer = _topics(graph, args)
    answer["typedefs_full_text"] = [full_text(k) for k in answer["types"]]
    return answer


def _topic_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    topic = _text(args, "topic", "/rosapi/topic_type")
    wanted = resolve_name(topic) if topic else ""
    return {"type": next((k for t, k in graph.topics if t == wanted), "")}


def _topics_for_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    try:
        wanted = normalize_type(_text(args, "type", "/rosapi/topics_for_type"))
    except TypeNameError:
        return {"topics": []}  # no topic has a type that is not one
    return {"topics": [t for t, k in graph.topics if k == wanted]}


def _all_services(graph: Graph) -> list[tuple[str, str]]:
    return [*graph.services, *ROSAPI_SERVICES.items()]


def _services(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"services": [s for s, _ in _all_services(graph)]}


def _service_type(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    service = _text(args, "service", "/rosapi/service_type")
    wanted = resolve_name(service) if service else ""
    return {"type": next((k for s, k in _all_services(graph) if s == wanted), "")}


def _nodes(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"nodes": list(graph.nodes)}


def _param_name(name: str) -> str:
    """``robot_description`` for ``robot_description``, ``/robot_description`` or
    ``/node:robot_description`` (ROS 2 rosapi's ``node:param``; any node of ours)."""
    return name.rsplit(":", 1)[-1].lstrip("/")


def _get_param(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    name = _text(args, "name", "/rosapi/get_param")
    default = _text(args, "default_value", "/rosapi/get_param")
    key = _param_name(name)
    if key in graph.params:
        return {"value": json.dumps(graph.params[key])}
    if default:
        return {"value": default}  # rosapi hands the default back as given (JSON text)
    known = ", ".join(sorted(graph.params)) or "none"
    raise RosapiError(f"/rosapi/get_param: no parameter {name!r} (parameters: {known})")


def _has_param(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    return {"exists": _param_name(_text(args, "name", "/rosapi/has_param")) in graph.params}


def _param_names(graph: Graph, args: Mapping[str, Any]) -> dict[str, Any]:
    node = graph.nodes[0] if graph.nodes else ""
    return {"names": [f"{node}:{name}" for name in sorted(graph.params)]}


_Answer = Callable[[Graph, Mapping[str, Any]], dict[str, Any]]
_ANSWERS: dict[str, tuple[str, _Answer]] = {
    "/rosapi/topics": ("Topics", _topics),
    "/rosapi/topics_and_raw_types": ("TopicsAndRawTypes", _topics_and_raw_types),
    "/rosapi/topic_type": ("TopicType", _topic_type),
    "/rosapi/topics_for_type": ("TopicsForType", _topics_for_type),
    "/rosapi/services": ("Services", _services),
    "/rosapi/service_type": ("ServiceType", _service_type),
    "/rosapi/nodes": ("Nodes", _nodes),
    "/rosapi/get_param": ("GetParam", _get_param),
    "/rosapi/has_param": ("HasParam", _has_param),
    "/rosapi/get_param_names": ("GetParamNames", _param_names),
}
ROSAPI_SERVICES: dict[str, str] = {
    name: f"rosapi_msgs/srv/{kind}" for name, (kind, _) in _ANSWERS.items()
}
"""The rosapi services c2rviz answers, with their ROS 2 types."""


def is_rosapi(service: str) -> bool:
    """Whether ``service`` (absolute) is one of the rosapi services answered here."""
    return service in _ANSWERS


def answer(service: str, args: Mapping[str, Any], graph: Graph) -> dict[str, Any]:
    """The response ``values`` of rosapi ``service`` called with ``args``.

    Args:
        service: An absolute service name for which ``is_rosapi`` holds.
        args: The request's fields (unknown fields are ignored, as rosapi does).
        graph: What there is to tell.

    Raises:
        RosapiError: Not a rosapi service answered here, a field of the wrong
            type, or ``get_param`` of an unknown parameter without a default.
    """
    entry = _ANSWERS.get(service)
    if entry is None:
        raise RosapiError(
            f"{service} is not a rosapi service c2rviz answers (it answers: {', '.join(_ANSWERS)})"
        )
    return entry[1](graph, args)
