"""The cameras in recordings and on ROS topics: the lines that place them again (NAME.txt)
and their reports as ROS messages (rosbridge's topics, the bag's).

A report is a ``geometry_msgs/msg/PoseArray`` whose header's ``frame_id`` is the camera's
frame ``cameras/NAME`` and whose poses are the seen parts' in it, with TF items: the
camera's frame in its parent's and each seen part's frame ``cameras/NAME/PART`` in the
camera's (docs/rosbridge.md says why a PoseArray).
"""

from __future__ import annotations

from collections.abc import Sequence

import pinocchio as pin

from ..robot.frames import se3_pose
from ..ros.messages import Msg, header
from ..world.cameras import Camera, Seen
from .bag_parts import xyz_xyzw

__all__ = [
    "CAMERA_FRAME",
    "CAMERA_TOPIC",
    "POSE_ARRAY",
    "CameraSignature",
    "camera_changes",
    "camera_items",
    "camera_signature",
    "pose_array",
]

POSE_ARRAY = "geometry_msgs/msg/PoseArray"
CAMERA_TOPIC = "/c2rviz/cameras/{name}"
CAMERA_FRAME = "cameras/{name}"

CameraSignature = dict[str, tuple[float, ...]]
"""Each camera's pose, view, rate and noise, by name (what NAME.txt has said)."""


def pose_array(t: float, name: str, seen: Sequence[Seen]) -> Msg:
    """``geometry_msgs/msg/PoseArray`` of what camera ``name`` sees, stamped ``t`` [s]."""
    poses = []
    for one in seen:
        (x, y, z), (qx, qy, qz, qw) = xyz_xyzw(one.pose)
        poses.append(
            {
                "position": {"x": float(x), "y": float(y), "z": float(z)},
                "orientation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
            }
        )
    return {"header": header(t, CAMERA_FRAME.format(name=name)), "poses": poses}


def camera_items(
    parent: str, to_parent: pin.SE3, camera: Camera, seen: Sequence[Seen]
) -> list[tuple[str, str, Sequence[float], Sequence[float]]]:
    """The camera's frame in ``parent`` and each seen part's in the camera's, as
    ``messages.transforms`` takes them."""
    frame = CAMERA_FRAME.format(name=camera.name)
    items = [(parent, frame, *xyz_xyzw(to_parent * camera.pose))]
    items += [(frame, f"{frame}/{one.name}", *xyz_xyzw(one.pose)) for one in seen]
    return items


def camera_signature(cameras: Sequence[Camera]) -> CameraSignature:
    return {
        c.name: (
            *se3_pose(c.pose),
            c.h_fov_rad,
            c.v_fov_rad,
            c.range_m,
            c.rate_hz,
            c.sigma_m,
            c.sigma_rad,
        )
        for c in cameras
    }


def _exact(values: Sequence[float]) -> str:
    return ",".join(repr(float(v)) for v in values)


def camera_changes(before: CameraSignature, cameras: Sequence[Camera]) -> str:
    """The commands (radians, world frame) from the cameras ``before`` to ``cameras``."""
    now = camera_signature(cameras)
    lines = [f"camera {name} remove\n" for name in before if name not in now]
    for name, values in now.items():
        if before.get(name) == values:
            continue
        lines.append(f"camera {name} {_exact(values[:6])} {_exact(values[6:9])}\n")
        lines.append(f"camera {name} rate {values[9]!r}\n")
        lines.append(f"camera {name} noise {_exact(values[10:12])}\n")
    return "".join(lines)
