"""ROS 2 message types by name, and the messages c2rviz takes, checked (pure).

Type names arrive in two spellings: ROS 1's ``sensor_msgs/JointState`` and
ROS 2's ``sensor_msgs/msg/JointState``; ``normalize_type`` makes the second of
either. The readers check one JSON message (as a dict) against its type and
return a small frozen dataclass in SI units (positions in [rad] or [m], times
in [s]); an error names the field, e.g. ``points[3].time_from_start is not
after points[2]``. Fields a type does not have are refused, as rosbridge does.

A large message is read off the event loop (``read_ahead``, by the connection that
decoded its frame there); ``remember`` keeps that reading so the reader, called
again on the loop with the very same message, returns it without reading twice. A
trajectory read there that names a joint its robot lacks comes back as its
``TrajectoryOutline`` (``outline``), not its points: it is refused, and its refusal
needs only that.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ...errors import C2rvizError

STRING = "std_msgs/msg/String"
JOINT_STATE = "sensor_msgs/msg/JointState"
JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
COMMAND_SERVICE_TYPE = "c2rviz_msgs/srv/Command"
"""The type c2rviz gives its ``/c2rviz/command`` service (request ``{command}``)."""

_PART = r"[A-Za-z][A-Za-z0-9_]*"
_TYPE = re.compile(rf"({_PART})/(?:(msg|srv|action)/)?({_PART})")
_NANOSECONDS_PER_SECOND = 1_000_000_000


class MessageError(C2rvizError):
    """A type name or a message that does not fit its type.

    Attributes:
        type_name: The type the message was read as.
        field: The field at fault (``points[2].positions[0]``), or "" for the whole.
        problem: What was wrong with it.
    """

    def __init__(self, type_name: str, field: str, problem: str) -> None:
        self.type_name, self.field, self.problem = type_name, field, problem
        where = f"{field} " if field else ""
        super().__init__(f"{type_name}: {where}{problem}")


class TypeNameError(C2rvizError):
    """A type name that is not ``pkg/Name`` or ``pkg/<kind>/Name`` of the kind wanted."""

    def __init__(self, name: str, problem: str) -> None:
        self.name, self.problem = name, problem
        shown = repr(name if len(name) <= 60 else name[:60] + "...")
        super().__init__(f"type {shown} {problem}")


def normalize_type(name: str, kind: str = "msg") -> str:
    """The ROS 2 spelling ``pkg/<kind>/Name`` of a type name given in either spelling.

    Args:
        name: ``pkg/Name`` or ``pkg/<kind>/Name``.
        kind: ``msg`` for a message type, ``srv`` for a service type.

    Raises:
        TypeNameError: Not a type name, or one of another kind.
    """
    match = _TYPE.fullmatch(name)
    if match is None:
        raise TypeNameError(
            name, f"is not a {kind} type name (package/Name or package/{kind}/Name)"
        )
    package, given, type_name = match.groups()
    if given is not None and given != kind:
        raise TypeNameError(name, f"is a {given} type, not a {kind} type")
    return f"{package}/{kind}/{type_name}"


def same_type(first: str, second: str, kind: str = "msg") -> bool:
    """Whether two type names (either spelling) name the same type."""
    return normalize_type(first, kind) == normalize_type(second, kind)


@dataclass(frozen=True)
class JointPositions:
    """Target positions by joint name (a ``sensor_msgs/msg/JointState`` taken as a command).

    Attributes:
        names: Joint names, each once.
        positions: One per name [rad] (revolute) or [m] (prismatic), finite.
    """

    names: tuple[str, ...]
    positions: tuple[float, ...]


@dataclass(frozen=True)
class TrajectoryPoint:
    """One timed point of a trajectory.

    Attributes:
        positions: One per joint name [rad] or [m].
        time_from_start_s: When to be there, from the trajectory's start [s].
        velocities: One per joint [rad/s] or [m/s], or None when not given.
        accelerations: One per joint [rad/s^2] or [m/s^2], or None when not given.
    """

    positions: tuple[float, ...]
    time_from_start_s: float
    velocities: tuple[float, ...] | None = None
    accelerations: tuple[float, ...] | None = None


@dataclass(frozen=True)
class JointTrajectory:
    """A ``trajectory_msgs/msg/JointTrajectory``: times strictly increase, all finite."""

    joint_names: tuple[str, ...]
    points: tuple[TrajectoryPoint, ...]


@dataclass(frozen=True)
class TrajectoryOutline:
    """A ``JointTrajectory`` without its points: what its refusal tells.

    Attributes:
        joint_names: Its joint names.
        point_count: How many points it has.
        duration_s: Its last point's ``time_from_start`` [s].
    """

    joint_names: tuple[str, ...]
    point_count: int
    duration_s: float

    @classmethod
    def of(cls, trajectory: JointTrajectory | TrajectoryOutline) -> TrajectoryOutline:
        """The outline of ``trajectory`` (an outline: itself)."""
        if isinstance(trajectory, TrajectoryOutline):
            return trajectory
        points = trajectory.points
        return cls(trajectory.joint_names, len(points), points[-1].time_from_start_s)


_READ_AHEAD: dict[int, tuple[Mapping[str, Any], object]] = {}
"""Messages read already (off the event loop, ``read_ahead``), by ``id``: the message
and its reading (or its ``MessageError``), until ``forget``."""


def read_ahead(
    type_name: str, msg: Mapping[str, Any], joints: Collection[str] | None = None
) -> object:
    """Read ``msg`` as ``type_name`` (on any thread): the dataclass its reader gives, the
    ``MessageError`` it raises, or None when c2rviz has no reader for the type; a
    trajectory naming a joint not in ``joints`` (its robot's), its ``TrajectoryOutline``."""
    reader = _READERS.get(type_name)
    if reader is None:
        return None
    try:
        reading = reader(msg)
    except MessageError as error:
        return error
    if (
        joints is not None
        and isinstance(reading, JointTrajectory)
        and any(name not in joints for name in reading.joint_names)
    ):
        return TrajectoryOutline.of(reading)
    return reading


def remember(msg: Mapping[str, Any], reading: object) -> None:
    """Keep what ``read_ahead`` gave for ``msg``: its reader then returns (or raises) it
    at once instead of reading ``msg`` again (on the event loop)."""
    _READ_AHEAD[id(msg)] = (msg, reading)


def forget(msg: Mapping[str, Any]) -> None:
    """Drop what ``remember`` kept for ``msg``."""
    _READ_AHEAD.pop(id(msg), None)


def outline(msg: Mapping[str, Any]) -> TrajectoryOutline | None:
    """The ``TrajectoryOutline`` that ``remember`` kept for this very message, else None
    (the ``MessageError`` kept for it as a trajectory: raised)."""
    return _known(msg, TrajectoryOutline, JOINT_TRAJECTORY)  # type: ignore[no-any-return]


def _known(msg: Mapping[str, Any], kind: type, type_name: str) -> Any:
    """The reading ``remember`` kept for this very message as ``type_name`` (a ``kind``,
    or its ``MessageError``, raised); else None."""
    kept = _READ_AHEAD.get(id(msg))
    if kept is None or kept[0] is not msg:
        return None
    if isinstance(kept[1], MessageError) and kept[1].type_name == type_name:
        raise kept[1]
    return kept[1] if isinstance(kept[1], kind) else None


class _Reader:
    """Checks fields of one message of ``type_name``; every error names its field."""

    def __init__(self, type_name: str) -> None:
        self.type_name = type_name

    def error(self, field: str, problem: str) -> MessageError:
        return MessageError(self.type_name, field, problem)

    def fields(self, value: object, field: str, allowed: Sequence[str]) -> Mapping[str, Any]:
        if not isinstance(value, dict):
            raise self.error(field, f"must be an object with fields {', '.join(allowed)}")
        extra = sorted(set(value) - set(allowed))
        if extra:
            where = f"{field} " if field else ""
            raise MessageError(
                self.type_name,
                "",
                f"{where}has no field {extra[0]!r} (fields: {', '.join(allowed)})",
            )
        return value

    def text(self, value: object, field: str) -> str:
        if not isinstance(value, str):
            raise self.error(field, "must be a string")
        return value

    def names(self, value: object, field: str) -> tuple[str, ...]:
        if not isinstance(value, list) or not value:
            raise self.error(field, "must be a non-empty array of joint names")
        names = tuple(self.text(item, f"{field}[{i}]") for i, item in enumerate(value))
        for i, name in enumerate(names):
            if not name:
                raise self.error(f"{field}[{i}]", "is empty")
            if name in names[:i]:
                raise self.error(f"{field}[{i}]", f"repeats joint {name!r}")
        return names

    def numbers(self, value: object, field: str, count: int, optional: bool) -> tuple[float, ...]:
        """``count`` finite numbers; with ``optional``, an empty array (or none) is ``()``."""
        if value is None and optional:
            return ()
        if not isinstance(value, list):
            raise self.error(field, "must be an array of numbers")
        if optional and not value:
            return ()
        if len(value) != count:
            raise self.error(field, f"has {len(value)} values for {count} joints")
        return tuple(self.number(item, f"{field}[{i}]") for i, item in enumerate(value))

    def number(self, value: object, field: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(field, "must be a number")
        try:
            number = float(value)
        except OverflowError:  # an integer of hundreds of digits: JSON allows it
            raise self.error(field, "is an integer too large for a float64") from None
        if not math.isfinite(number):
            raise self.error(field, f"is not finite ({number})")
        return number

    def integer(self, value: object, field: str, low: int, high: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(field, "must be an integer")
        if not low <= value <= high:
            raise self.error(field, f"{value} is outside {low}..{high}")
        return value

    def duration_s(self, value: object, field: str) -> float:
        time = self.fields(value, field, ("sec", "nanosec"))
        sec = self.integer(time.get("sec", 0), f"{field}.sec", 0, 2**31 - 1)
        nanosec = self.integer(
            time.get("nanosec", 0), f"{field}.nanosec", 0, _NANOSECONDS_PER_SECOND - 1
        )
        return sec + nanosec / _NANOSECONDS_PER_SECOND

    def header(self, value: object, field: str) -> None:
        if value is None:
            return
        header = self.fields(value, field, ("stamp", "frame_id"))
        if "stamp" in header:
            stamp = self.fields(header["stamp"], f"{field}.stamp", ("sec", "nanosec"))
            self.integer(stamp.get("sec", 0), f"{field}.stamp.sec", -(2**31), 2**31 - 1)
            self.integer(
                stamp.get("nanosec", 0), f"{field}.stamp.nanosec", 0, _NANOSECONDS_PER_SECOND - 1
            )
        if "frame_id" in header:
            self.text(header["frame_id"], f"{field}.frame_id")


def string_data(msg: Mapping[str, Any]) -> str:
    """The text of a ``std_msgs/msg/String`` (``{"data": text}``)."""
    reader = _Reader(STRING)
    fields = reader.fields(msg, "", ("data",))
    if "data" not in fields:
        raise reader.error("data", "is missing")
    return reader.text(fields["data"], "data")


def joint_positions(msg: Mapping[str, Any]) -> JointPositions:
    """The targets of a ``sensor_msgs/msg/JointState`` taken as a command.

    ``name`` and ``position`` are needed and of one length; ``velocity`` and
    ``effort`` may be empty or absent, else of that length too (checked, not used).
    """
    known = _known(msg, JointPositions, JOINT_STATE)
    if known is not None:
        return known  # type: ignore[no-any-return]
    reader = _Reader(JOINT_STATE)
    fields = reader.fields(msg, "", ("header", "name", "position", "velocity", "effort"))
    reader.header(fields.get("header"), "header")
    names = reader.names(fields.get("name"), "name")
    positions = reader.numbers(fields.get("position"), "position", len(names), optional=False)
    reader.numbers(fields.get("velocity"), "velocity", len(names), optional=True)
    reader.numbers(fields.get("effort"), "effort", len(names), optional=True)
    return JointPositions(names, positions)


def joint_trajectory(msg: Mapping[str, Any]) -> JointTrajectory:
    """A ``trajectory_msgs/msg/JointTrajectory``, checked whole.

    Every point needs ``positions`` (one per joint) and ``time_from_start``;
    times are at least 0 and strictly increase; ``velocities``,
    ``accelerations`` and ``effort`` may be empty, else one per joint.
    """
    known = _known(msg, JointTrajectory, JOINT_TRAJECTORY)
    if known is not None:
        return known  # type: ignore[no-any-return]
    reader = _Reader(JOINT_TRAJECTORY)
    fields = reader.fields(msg, "", ("header", "joint_names", "points"))
    reader.header(fields.get("header"), "header")
    names = reader.names(fields.get("joint_names"), "joint_names")
    raw_points = fields.get("points")
    if not isinstance(raw_points, list) or not raw_points:
        raise reader.error("points", "must be a non-empty array of trajectory points")
    keys = ("positions", "velocities", "accelerations", "effort", "time_from_start")
    points: list[TrajectoryPoint] = []
    for i, raw in enumerate(raw_points):
        at = f"points[{i}]"
        point = reader.fields(raw, at, keys)
        if "time_from_start" not in point:
            raise reader.error(f"{at}.time_from_start", "is missing")
        time_s = reader.duration_s(point["time_from_start"], f"{at}.time_from_start")
        if points and time_s <= points[-1].time_from_start_s:
            raise reader.error(f"{at}.time_from_start", f"is not after points[{i - 1}]")
        positions = reader.numbers(point.get("positions"), f"{at}.positions", len(names), False)
        velocities = reader.numbers(point.get("velocities"), f"{at}.velocities", len(names), True)
        accelerations = reader.numbers(
            point.get("accelerations"), f"{at}.accelerations", len(names), True
        )
        reader.numbers(point.get("effort"), f"{at}.effort", len(names), True)
        points.append(TrajectoryPoint(positions, time_s, velocities or None, accelerations or None))
    return JointTrajectory(names, tuple(points))


_READERS: dict[str, Callable[[Mapping[str, Any]], object]] = {
    JOINT_STATE: joint_positions,
    JOINT_TRAJECTORY: joint_trajectory,
}


def command_request(args: Mapping[str, Any]) -> str:
    """The command line of a ``/c2rviz/command`` service request (``{"command": line}``)."""
    reader = _Reader(COMMAND_SERVICE_TYPE + "_Request")
    fields = reader.fields(args, "", ("command",))
    if "command" not in fields:
        raise reader.error("command", "is missing")
    return reader.text(fields["command"], "command")


def command_response(reply: str, ok: bool) -> dict[str, Any]:
    """The ``/c2rviz/command`` service response: the reply, and ``ok`` unless it is an error."""
    return {"reply": reply, "ok": ok}
