"""ROS 2 message definitions (``.msg`` text) of the types c2rviz publishes and takes (pure).

``full_text`` gives a type's definition followed by those of every type it
uses, in the layout rosapi's ``/rosapi/topics_and_raw_types`` sends (and
``gendeps --cat`` and rosbag2's MCAP schemas use): the root's text, then for
each dependency a line of 80 ``=``, a line ``MSG: package/Name`` and its text.
The fields are those of ROS 2 Humble's interfaces (comments left out).
Foxglove and Lichtblick read this text to decode a topic's messages.
"""

from __future__ import annotations

from .messages import TypeNameError, normalize_type

__all__ = ["DEFINITIONS", "dependencies", "full_text"]

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
