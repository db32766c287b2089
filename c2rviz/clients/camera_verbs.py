"""The calls of logical cameras (pure: arguments checked before anything is sent) and their
records; the clients' methods that send them are in ``aio_scene_verbs`` (and its blocking
twin, ``scene_verbs``). docs/cameras.md has the rules.

A camera's pose is in the world frame: x, y, z [m], roll, pitch, yaw in the connection's
angle unit; fields of view in that unit too; what it sees is in the camera's frame.
"""

from __future__ import annotations

from typing import NamedTuple

from . import arguments as check
from .calls import Call, fixed, parsed, pose_text
from .errors import ArgumentError

__all__ = ["CameraInfo", "Seen"]


class Seen(NamedTuple):
    """A part a camera sees: its ``name``, ``type`` (its shape when it has none) and
    ``pose`` in the camera's frame (x, y, z [m], roll, pitch, yaw [rad, or deg])."""

    name: str
    type: str
    pose: tuple[float, ...]


class CameraInfo(NamedTuple):
    """A camera: ``pose`` (world frame), ``fov`` (h_fov, v_fov [rad, or deg], range [m])
    and ``rate`` [Hz]."""

    pose: tuple[float, ...]
    fov: tuple[float, ...]
    rate: float


def _numbers(text: str, count: int, reply: str) -> tuple[float, ...]:
    values = tuple(float(v) for v in text.split(","))
    if len(values) != count:
        raise ValueError(reply)
    return values


def read_seen(reply: str) -> list[Seen]:
    """``ok p1:battery:x,y,z,roll,pitch,yaw;...`` (``ok none``)."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    seen = []
    for item in [] if body == "none" else body.split(";"):
        name, kind, pose = item.split(":")
        seen.append(Seen(name, kind, _numbers(pose, 6, reply)))
    return seen


def read_cameras(reply: str) -> dict[str, CameraInfo]:
    """``ok NAME:x,y,z,roll,pitch,yaw:h_fov,v_fov,range:RATE;...`` (``ok none``)."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    found = {}
    for item in [] if body == "none" else body.split(";"):
        name, pose, fov, rate = item.split(":")
        found[name] = CameraInfo(_numbers(pose, 6, reply), _numbers(fov, 3, reply), float(rate))
    return found


def _ok(reply: str) -> None:
    if reply != "ok":
        raise ValueError(reply)


def add_camera(name: object, pose: object, fov: object) -> Call[None]:
    chosen = check.word("add_camera", "name", name)
    line = f"camera {chosen} {pose_text('add_camera', 'pose', pose)}"
    if fov is not None:
        given = check.values("add_camera", "fov", fov)
        if len(given) != 3:
            raise ArgumentError(
                "add_camera", "fov", f"needs 3 values (h, v, range), got {len(given)}"
            )
        line += f" {check.numbers_text(given)}"
    return Call(parsed("add_camera", "name", line), _ok)


def camera(name: object) -> Call[list[Seen]]:
    chosen = check.word("camera", "name", name)
    return Call(parsed("camera", "name", f"camera {chosen}"), read_seen)


def remove_camera(name: object) -> Call[None]:
    chosen = check.word("remove_camera", "name", name)
    return Call(parsed("remove_camera", "name", f"camera {chosen} remove"), _ok)


def camera_rate(name: object, hz: object) -> Call[None]:
    chosen = check.word("camera_rate", "name", name)
    rate = check.number("camera_rate", "hz", hz)
    return Call(parsed("camera_rate", "hz", f"camera {chosen} rate {rate!r}"), _ok)


def camera_noise(name: object, sigma_m: object, sigma_angle: object) -> Call[None]:
    chosen = check.word("camera_noise", "name", name)
    sigmas = (
        check.number("camera_noise", "sigma_m", sigma_m),
        check.number("camera_noise", "sigma_angle", sigma_angle),
    )
    line = f"camera {chosen} noise {check.numbers_text(sigmas)}"
    return Call(parsed("camera_noise", "sigma_m", line), _ok)


CAMERAS = fixed("cameras", read_cameras)
