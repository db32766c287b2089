"""The calls of a task beyond moving the arm: planning, the guard's modes, the gripper, the
ghost and faults (docs/faults.md); parts, goals, the score and logical cameras
(docs/parts.md, docs/cameras.md). Pure (arguments checked before anything is sent), with
their records; the clients' methods that send them are in ``aio_verbs`` and
``aio_scene_verbs`` (and their blocking twins, ``verbs`` and ``scene_verbs``).

Angles and a fault's noise are in the connection's unit (radians unless the client chose
degrees), lengths in metres, times in seconds (of the server's clock), a fault's latency
in milliseconds. A part's pose is in the connection's robot's base frame: x, y, z [m],
roll, pitch, yaw in the connection's angle unit; sizes in metres. A camera's pose is in
the world frame: x, y, z [m], roll, pitch, yaw in the connection's angle unit; fields of
view in that unit too; what it sees is in the camera's frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from ..protocol.verbs.faults import FAULT_KINDS
from . import errors as check
from . import records as read
from .calls import OBJECT_SHAPES, Call, fixed, parsed, pose_text, with_value
from .errors import ArgumentError

GUARD_MODES = ("on", "off", "plan")


class PlanSummary(NamedTuple):
    """A planned path: its ``waypoints``, its joint-space ``length`` in ``unit`` (``rad``
    whatever the connection's unit, as the server says) and its ``duration`` [s]."""

    waypoints: int
    length: float
    unit: str
    duration: float


def read_plan_summary(reply: str) -> PlanSummary:
    """``ok 3 waypoints 4.816 rad 3.485 s``."""
    count, word, length, unit, duration, seconds = reply.removeprefix("ok ").split(" ")
    if not reply.startswith("ok ") or word != "waypoints" or seconds != "s":
        raise ValueError(reply)
    return PlanSummary(int(count), float(length), unit, float(duration))


def read_waypoints(reply: str) -> list[tuple[float, ...]]:
    """``ok q0;q1;...``: each waypoint's joint values."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    return [tuple(map(float, q.split(","))) for q in reply[3:].split(";")]


def plan_joints(values: object) -> Call[PlanSummary]:
    given = check.values("plan_joints", "values", values)
    line = "plan joints " + check.numbers_text(given)
    return Call(line, read_plan_summary, joint_count=("plan_joints", "values", len(given)))


def plan_pose(pose: object) -> Call[PlanSummary]:
    text = pose_text("plan_pose", "pose", pose, (3, 6))
    return Call(f"plan pose {text}", read_plan_summary)


def plan_timeout(seconds: object) -> Call[float]:
    if seconds is None:
        return fixed("plan timeout", read.read_number)
    value = check.number("plan_timeout", "seconds", seconds)
    return Call(parsed("plan_timeout", "seconds", f"plan timeout {value!r}"), with_value(value))


def plan_resolution(steps: object) -> Call[tuple[float, ...]]:
    if steps is None:
        return fixed("plan resolution", read.read_numbers)
    given = check.values("plan_resolution", "steps", steps, 2)
    line = f"plan resolution {check.numbers_text(given)}"
    return Call(parsed("plan_resolution", "steps", line), with_value(given))


def guard_mode(mode: object) -> Call[str]:
    if mode is None:
        return fixed("guard", read.read_word)
    chosen = check.choice("guard_mode", "mode", mode, GUARD_MODES)
    return Call(f"guard {chosen}", with_value(chosen))


def grip(opening: object) -> Call[float]:
    if opening is None:
        return fixed("grip", read.read_number)
    value = check.number("grip", "opening", opening)
    return Call(parsed("grip", "opening", f"grip {value!r}"), with_value(value))


def ghost(on: object) -> Call[bool]:
    if on is None:
        return fixed("ghost", read.read_on_off)
    chosen = check.flag("ghost", "on", on)
    return Call(f"ghost {'on' if chosen else 'off'}", with_value(chosen))


PLAN = fixed("plan", read_waypoints)


def read_faults(reply: str) -> list[str]:
    """``ok none`` -> []; ``ok estop since 1.500; noise 0.01 at 5.000`` -> each item."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    return [] if body == "none" else body.split("; ")


def fault(kind: object, args: tuple[object, ...], at: object, after: object) -> Call[None]:
    chosen = check.choice("fault", "kind", kind, tuple(FAULT_KINDS))
    words = ["fault"]
    if at is not None:
        words += ["at", repr(check.number("fault", "at", at))]
    if after is not None:
        words += ["after", repr(check.number("fault", "after", after))]
    words.append(chosen)
    if args:
        if not any(isinstance(a, str) for a in args):
            words.append(",".join(repr(check.number("fault", "args", a)) for a in args))
        else:
            words.extend(str(a) for a in args)
    return Call(parsed("fault", "args", " ".join(words)), read.read_ok)


def clear_faults(kind: object) -> Call[None]:
    chosen = check.choice("clear_faults", "kind", kind, (*FAULT_KINDS, "all"))
    return Call(f"fault clear {chosen}", read.read_ok)


FAULTS = fixed("faults", read_faults)
RESET = fixed("reset", read.read_ok)


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
