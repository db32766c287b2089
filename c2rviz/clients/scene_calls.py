"""The calls of parts, goals, the score and logical cameras (pure: arguments checked
before anything is sent) and their records; the clients' methods that send them are in
``aio_scene_verbs`` (and its blocking twin, ``scene_verbs``). docs/parts.md and
docs/cameras.md have the rules.

A part's pose is in the connection's robot's base frame: x, y, z [m], roll, pitch, yaw in
the connection's angle unit (radians unless the client chose degrees); sizes in metres.
A camera's pose is in the world frame: x, y, z [m], roll, pitch, yaw in the connection's
angle unit; fields of view in that unit too; what it sees is in the camera's frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from . import arguments as check
from .calls import OBJECT_SHAPES, Call, fixed, parsed, pose_text
from .errors import ArgumentError

__all__ = ["CameraInfo", "PartState", "Score", "Seen"]


_SIZES = {"box": 3, "sphere": 1, "cylinder": 2}


class PartState(NamedTuple):
    """Where a part is and what holds it: ``pose`` (x, y, z [m], roll, pitch, yaw [rad, or
    deg in degrees mode], base frame) and ``state`` (``free``, ``held`` or ``resting on
    WHAT``)."""

    pose: tuple[float, ...]
    state: str


class Score(NamedTuple):
    """``score``: ``met`` of ``total`` goals met; ``off`` the server's words for each
    goal not met (``p2 12.1 mm 3.0 deg off``, ``p4 missing``)."""

    met: int
    total: int
    off: tuple[str, ...]


def read_part(reply: str) -> PartState:
    """``ok x,y,z,roll,pitch,yaw STATE``."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    pose, _, state = reply[3:].partition(" ")
    values = tuple(float(v) for v in pose.split(","))
    if len(values) != 6 or not state:
        raise ValueError(reply)
    return PartState(values, state)


def read_parts(reply: str) -> dict[str, PartState]:
    """``ok NAME:x,y,z,roll,pitch,yaw:STATE;...`` (``ok none``)."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    found: dict[str, PartState] = {}
    for item in [] if body == "none" else body.split(";"):
        name, pose, state = item.split(":", 2)
        found[name] = read_part(f"ok {pose} {state}")
    return found


def read_score(reply: str) -> Score:
    """``ok 3/4 met; p2 12.1 mm 3.0 deg off; p4 missing`` (``ok no goals``: 0 of 0)."""
    if reply == "ok no goals":
        return Score(0, 0, ())
    if not reply.startswith("ok "):
        raise ValueError(reply)
    head, *off = reply[3:].split("; ")
    met, slash, total = head.removesuffix(" met").partition("/")
    if not slash:
        raise ValueError(reply)
    return Score(int(met), int(total), tuple(off))


def _ok(reply: str) -> None:
    if reply != "ok":
        raise ValueError(reply)


def add_part(
    name: object,
    shape: object,
    size: object,
    pose: object,
    kind: object = None,
    color: object = None,
) -> Call[None]:
    chosen = check.word("add_part", "name", name)
    form = check.choice("add_part", "shape", shape, OBJECT_SHAPES)
    if isinstance(size, (int, float)) and not isinstance(size, bool):
        dims: tuple[float, ...] = (check.number("add_part", "size", size),)
    else:
        dims = check.values("add_part", "size", size)
    if len(dims) != _SIZES[form]:
        raise ArgumentError("add_part", "size", f"a {form} needs {_SIZES[form]} size values")
    where = pose_text("add_part", "pose", pose, (3, 6) if form == "sphere" else (6,))
    line = f"part {chosen} {form} {check.numbers_text(dims)} {where}"
    if kind is not None:
        line += f" type={check.word('add_part', 'kind', kind)}"
    if color is not None:
        line += f" color={check.numbers_text(check.values('add_part', 'color', color))}"
    return Call(parsed("add_part", "name", line), _ok)


def part(name: object) -> Call[PartState]:
    chosen = check.word("part", "name", name)
    return Call(parsed("part", "name", f"part {chosen}"), read_part)


def remove_part(name: object) -> Call[None]:
    chosen = check.word("remove_part", "name", name)
    return Call(parsed("remove_part", "name", f"part {chosen} remove"), _ok)


def goal(target: object, pose: object, tol: Sequence[float] | None) -> Call[None]:
    chosen = check.word("goal", "target", target)
    line = f"goal {chosen} {pose_text('goal', 'pose', pose)}"
    if tol is not None:
        given = check.values("goal", "tol", tol)
        if len(given) != 2:
            raise ArgumentError("goal", "tol", f"needs 2 values (metres, angle), got {len(given)}")
        line += f" {check.numbers_text(given)}"
    return Call(parsed("goal", "target", line), _ok)


def remove_goal(target: object) -> Call[None]:
    chosen = check.word("remove_goal", "target", target)
    return Call(parsed("remove_goal", "target", f"goal {chosen} remove"), _ok)


PARTS = fixed("parts", read_parts)
REMOVE_PARTS = fixed("part all remove", _ok)
REMOVE_GOALS = fixed("goal all remove", _ok)
SCORE = fixed("score", read_score)


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
