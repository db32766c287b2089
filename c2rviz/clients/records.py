"""The typed records a ``Client`` returns, and how each is read from its reply.

Angles are in the connection's unit (radians unless the client chose degrees),
lengths in metres, times in seconds. Each ``read_*`` takes the whole reply line
(``ok ...``) and raises ``ValueError`` when it is not the shape a c2rviz server
sends (the client turns that into ``UnexpectedReply``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple


class Pose(NamedTuple):
    """A tool pose: position [m] and roll, pitch, yaw [rad, or deg in degrees mode]."""

    x: float
    y: float
    z: float
    roll: float
    pitch: float
    yaw: float


class JointLimit(NamedTuple):
    """One chain joint's range, in the connection's units: ``lower``, ``upper`` [rad, deg
    or m] and the ``unit`` (``rad``, ``deg`` or ``m``)."""

    lower: float
    upper: float
    unit: str


class MotionLimit(NamedTuple):
    """One chain joint's motion limits, in the connection's units: ``velocity`` [unit/s],
    ``acceleration`` [unit/s^2], ``jerk`` [unit/s^3]."""

    velocity: float
    acceleration: float
    jerk: float


class RobotNames(NamedTuple):
    """The robot a connection drives and its chain's joint names, in index order."""

    robot: str
    joints: tuple[str, ...]


class VersionInfo(NamedTuple):
    """The server's version and the robot file it loaded (name and SHA-256 prefix)."""

    c2rviz: str
    robot_file: str
    sha256: str


class MotionStatus(NamedTuple):
    """Whether the arm moves, and the time until it is at rest [s of the server's clock]."""

    moving: bool
    seconds_left: float


class TrailStatus(NamedTuple):
    """Whether the robot's trail is on, and its points."""

    on: bool
    points: int


class RecordingStatus(NamedTuple):
    """The recording running: its name and how long it has run [s of the server's clock]."""

    name: str
    seconds: float


class RecordingResult(NamedTuple):
    """A finished recording: its name, rows, length [s] and the files the server wrote."""

    name: str
    frames: int
    seconds: float
    files: tuple[Path, ...]


@dataclass(frozen=True, slots=True)
class State:
    """A ``watch`` state line: the arm at ``t`` [s since the server started, on its clock].

    Attributes:
        t: The time [s].
        values: The chain's joints, in the watching connection's units.
    """

    t: float
    values: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Event:
    """A ``watch`` event line: ``event KIND DETAIL``.

    Attributes:
        kind: ``marker``, ``clear``, ``arrived``, ``stopped``, ``collision``,
            ``record-stopped``, ``dropped`` (and any kind a newer server adds).
        detail: The rest of the line (``link_t~table`` for a collision).
    """

    kind: str
    detail: str = ""

    @property
    def pairs(self) -> list[tuple[str, str]]:
        """A collision event's colliding pairs (empty for ``none`` and other kinds)."""
        return read_pairs(self.detail) if self.kind == "collision" else []


def _payload(reply: str) -> str:
    if not reply.startswith("ok "):
        raise ValueError(reply)
    return reply[3:]


def read_ok(reply: str) -> None:
    if reply != "ok" and not reply.startswith("ok "):
        raise ValueError(reply)


def read_numbers(reply: str) -> tuple[float, ...]:
    return tuple(map(float, _payload(reply).split(",")))


def read_number(reply: str) -> float:
    (value,) = read_numbers(reply)
    return value


def read_pose(reply: str) -> Pose:
    return Pose(*read_numbers(reply))


def read_word(reply: str) -> str:
    word = _payload(reply)
    if not word or " " in word:
        raise ValueError(reply)
    return word


def read_limits(reply: str) -> list[JointLimit]:
    """``ok -1.5..1.5 rad,...`` (``limits``; the motion limits of ``limits all`` ignored)."""
    limits = []
    for item in _payload(reply).split(","):
        span, unit, *_ = item.split(" ")
        lower, upper = span.split("..")
        limits.append(JointLimit(float(lower), float(upper), unit))
    return limits


def read_motion_limits(reply: str) -> list[MotionLimit]:
    """``ok -1.5..1.5 rad v=2 a=4 j=20,...`` (``limits all``)."""
    limits = []
    for item in _payload(reply).split(","):
        rates = dict(rate.split("=") for rate in item.split(" ")[2:])
        limits.append(MotionLimit(float(rates["v"]), float(rates["a"]), float(rates["j"])))
    return limits


def read_names(reply: str) -> RobotNames:
    robot, joints = _payload(reply).split(" ")
    return RobotNames(robot, tuple(joints.split(",")))


def read_version(reply: str) -> VersionInfo:
    c2rviz, version, robot_file, digest = _payload(reply).split(" ")
    if c2rviz != "c2rviz" or not digest.startswith("sha256:"):
        raise ValueError(reply)
    return VersionInfo(version, robot_file, digest.removeprefix("sha256:"))


def read_help(reply: str) -> list[str]:
    if not reply.startswith("ok commands: "):
        raise ValueError(reply)
    return reply.removeprefix("ok commands: ").split("; ")


def read_pairs(text: str) -> list[tuple[str, str]]:
    if text == "none":
        return []
    pairs = []
    for pair in text.split(","):
        first, second = pair.split("~")
        pairs.append((first, second))
    return pairs


def read_collisions(reply: str) -> list[tuple[str, str]]:
    return read_pairs(_payload(reply))


def read_objects(reply: str) -> list[str]:
    names = _payload(reply)
    return [] if names == "none" else names.split(",")


def read_robots(reply: str) -> dict[str, int | None]:
    robots: dict[str, int | None] = {}
    for item in _payload(reply).split(","):
        name, colon, port = item.partition(":")
        robots[name] = int(port) if colon else None
    return robots


def read_on_off(reply: str) -> bool:
    word = read_word(reply)
    if word not in ("on", "off"):
        raise ValueError(reply)
    return word == "on"


def read_guard(reply: str) -> bool:
    """``ok on``, ``ok plan`` (on, and planning around what it refuses) or ``ok off``."""
    word = read_word(reply)
    if word not in ("on", "off", "plan"):
        raise ValueError(reply)
    return word != "off"


def read_status(reply: str) -> MotionStatus:
    words = _payload(reply).split(" ")
    if words == ["idle"]:
        return MotionStatus(False, 0.0)
    kind, seconds = words
    if kind != "moving":
        raise ValueError(reply)
    return MotionStatus(True, float(seconds))


def read_trail(reply: str) -> TrailStatus:
    words = _payload(reply).split(" ")
    if words == ["off"]:
        return TrailStatus(False, 0)
    on, points = words
    if on != "on":
        raise ValueError(reply)
    return TrailStatus(True, int(points))


def read_recording(reply: str) -> RecordingStatus | None:
    payload = _payload(reply)
    if payload == "not recording":
        return None
    kind, name, seconds = payload.split(" ")
    if kind != "recording":
        raise ValueError(reply)
    return RecordingStatus(name, float(seconds))


def read_record_folder(reply: str) -> Path:
    kind, _name, into, folder = _payload(reply).split(" ", 3)
    if kind != "recording" or into != "into":
        raise ValueError(reply)
    return Path(folder)


def read_recorded(reply: str) -> RecordingResult:
    """``ok recorded NAME: N frames, S s (PATH, PATH, ...)``."""
    head, _, files = _payload(reply).partition(" (")
    kind, name, frames, _frames, seconds, _s = head.replace(",", "").split(" ")
    if kind != "recorded" or not name.endswith(":") or not files.endswith(")"):
        raise ValueError(reply)
    paths = tuple(Path(path) for path in files[:-1].split(", "))
    return RecordingResult(name[:-1], int(frames), float(seconds), paths)


def read_stream_line(line: str) -> State | Event | None:
    """A ``watch`` stream line as a record (None: not a stream line, e.g. a reply)."""
    if line.startswith("state "):
        _, t, values = line.split(" ")
        return State(float(t), tuple(map(float, values.split(","))))
    if line.startswith("event "):
        kind, _, detail = line[6:].partition(" ")
        return Event(kind, detail)
    return None
