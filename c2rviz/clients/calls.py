"""Each verb as a call: its arguments checked and written as a line, and its reply read.

Pure (no sockets): ``Client`` and ``AsyncClient`` both send a ``Call``'s ``line`` and
hand the reply to its ``read``. Arguments are checked here, before anything is sent:
types and counts by ``errors``'s checks, ranges and words by the server's own parser
(``protocol.parse_line``), whose complaint becomes an ``ArgumentError`` naming the
argument. A joint count is checked against the robot's by the client
(``Call.joint_count``), which knows it from ``names``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from ..errors import BadArguments, C2rvizError
from ..protocol.grammar import MARKER_SHAPES, parse_line
from ..protocol.verbs.arm import MOTION_MODES, RobotChoice
from ..protocol.verbs.scene import TRAIL_ACTIONS
from ..protocol.verbs.seed import Units
from . import errors as check
from . import records as read
from .errors import ArgumentError, CommandError, UnexpectedReply

T = TypeVar("T")
F = TypeVar("F", bound=Callable[..., object])

OBJECT_SHAPES = ("box", "sphere", "cylinder")


@dataclass(frozen=True)
class Call(Generic[T]):
    """One command line and how its ``ok`` reply is read.

    Attributes:
        line: The line to send (no newline).
        read: Reads the ``ok`` reply (raises ``ValueError`` for one of another shape).
        track: A ``Units`` or ``RobotChoice`` command: the client remembers it once ``ok``.
        joint_count: (method, argument, how many values were given), when that must be
            the robot's joint count.
        highest_index: (method, argument, index), when that must be a joint of the robot.
    """

    line: str
    read: Callable[[str], T]
    track: object = None
    joint_count: tuple[str, str, int] | None = None
    highest_index: tuple[str, str, int] | None = None
    data: bytes = b""
    """The line as sent: encoded, with its newline."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "data", self.line.encode() + b"\n")


def with_value(value: T) -> Callable[[str], T]:
    """A reader for a setting's ``ok``: returns the value set."""

    def read_set(reply: str) -> T:
        read.read_ok(reply)
        return value

    return read_set


def fixed(line: str, reader: Callable[[str], T]) -> Call[T]:
    return Call(line, reader)


def parsed(method: str, argument: str, line: str) -> str:
    """``line`` if the server's parser takes it; else its complaint, naming ``argument``."""
    try:
        parse_line(line)
    except BadArguments as exc:
        raise ArgumentError(method, argument, exc.problem) from None
    except C2rvizError as exc:
        raise ArgumentError(method, argument, str(exc)) from None
    return line


def pose_text(method: str, argument: str, pose: object, sizes: Sequence[int] = (6,)) -> str:
    """A pose (x, y, z [m], roll, pitch, yaw [the connection's angle unit]) as text."""
    values = check.values(method, argument, pose)
    if len(values) not in sizes:
        wanted = " or ".join(map(str, sizes))
        raise ArgumentError(method, argument, f"needs {wanted} values, got {len(values)}")
    return check.numbers_text(values)


# The calls that take nothing: one object each, made once.

OK_ONLY = read.read_ok
WHERE = fixed("where", read.read_numbers)
POSE = fixed("pose", read.read_pose)
NAMES = fixed("names", read.read_names)
VERSION = fixed("version", read.read_version)
HELP = fixed("help", read.read_help)
TARGET = fixed("target", read.read_numbers)
STATUS = fixed("status", read.read_status)
OBJECTS = fixed("objects", read.read_objects)
COLLISIONS = fixed("collisions", read.read_collisions)
ROBOTS = fixed("robots", read.read_robots)
RECORDING = fixed("record", read.read_recording)
RECORD_STOP = fixed("record stop", read.read_recorded)
TRAIL_STATUS = fixed("trail", read.read_trail)
HOME = fixed("home", OK_ONLY)
RAND = fixed("rand", OK_ONLY)
CLEAR = fixed("clear", OK_ONLY)
STOP = fixed("stop", OK_ONLY)
WAIT = fixed("wait", OK_ONLY)
BYE = fixed("bye", OK_ONLY)
QUIT = fixed("quit", OK_ONLY)
UNWATCH = fixed("unwatch", OK_ONLY)
DEGREES = Call("degrees", OK_ONLY, track=Units(degrees=True))
RADIANS = Call("radians", OK_ONLY, track=Units(degrees=False))


def joints(values: object) -> Call[None]:
    given = check.values("joints", "values", values)
    return Call(
        "joints " + check.numbers_text(given),
        OK_ONLY,
        joint_count=("joints", "values", len(given)),
    )


def move(indices: object, values: object) -> Call[None]:
    chosen = check.indices("move", "indices", indices)
    given = check.values("move", "values", values, len(chosen))
    if len(set(chosen)) != len(chosen):
        raise ArgumentError("move", "indices", "an index is given twice")
    line = f"move {','.join(map(str, chosen))} {check.numbers_text(given)}"
    return Call(line, OK_ONLY, highest_index=("move", "indices", max(chosen)))


def mark(pose: object, world: bool) -> Call[None]:
    in_world = check.flag("mark", "world", world)
    if pose is None:
        if in_world:
            raise ArgumentError("mark", "pose", "world=True needs a pose")
        return Call("mark", OK_ONLY)
    text = pose_text("mark", "pose", pose)
    return Call(f"mark world {text}" if in_world else f"mark {text}", OK_ONLY)


def color(verb: str, rgb: tuple[object, object, object]) -> Call[None]:
    channels = [check.number(verb, name, value) for name, value in zip("rgb", rgb)]
    line = f"{verb} {check.numbers_text(channels)}"
    return Call(parsed(verb, "r, g, b", line), OK_ONLY)


def marker(shape: object) -> Call[None]:
    return Call(f"marker {check.choice('marker', 'shape', shape, MARKER_SHAPES)}", OK_ONLY)


LIMITS = fixed("limits", read.read_limits)
MOTION_LIMITS = fixed("limits all", read.read_motion_limits)


def sleep(seconds: object) -> Call[None]:
    value = check.number("sleep", "seconds", seconds)
    return Call(parsed("sleep", "seconds", f"sleep {value!r}"), OK_ONLY)


def tool(pose: object) -> Call[read.Pose]:
    if pose is None:
        return fixed("tool", read.read_pose)
    text = pose_text("tool", "pose", pose)
    return Call(f"tool {text}", with_value(read.Pose(*map(float, text.split(",")))))


def ik(pose: object) -> Call[tuple[float, ...]]:
    return fixed(f"ik {pose_text('ik', 'pose', pose)}", read.read_numbers)


def moveto(pose: object, marker: object) -> Call[None]:
    if (pose is None) == (marker is None):
        raise ArgumentError("moveto", "pose", "give a pose or marker=N, not both or neither")
    if marker is not None:
        (index,) = check.indices("moveto", "marker", marker)
        return Call(parsed("moveto", "marker", f"moveto marker {index}"), OK_ONLY)
    return Call(f"moveto {pose_text('moveto', 'pose', pose)}", OK_ONLY)


def movel(pose: object) -> Call[None]:
    return Call(f"movel {pose_text('movel', 'pose', pose)}", OK_ONLY)


def setting(verb: str, argument: str, value: object, reader: Callable[[str], Any]) -> Call[Any]:
    """A verb that alone replies its setting and with a number sets it (speed, lspeed)."""
    if value is None:
        return fixed(verb, reader)
    number = check.number(verb, argument, value)
    return Call(parsed(verb, argument, f"{verb} {number!r}"), with_value(number))


def motion(mode: object) -> Call[str]:
    if mode is None:
        return fixed("motion", read.read_word)
    chosen = check.choice("motion", "mode", mode, MOTION_MODES)
    return Call(f"motion {chosen}", with_value(chosen))


def guard(on: object) -> Call[bool]:
    if on is None:
        return fixed("guard", read.read_guard)
    chosen = check.flag("guard", "on", on)
    return Call(f"guard {'on' if chosen else 'off'}", with_value(chosen))


def robot(name: object) -> Call[str]:
    if name is None:
        return fixed("robot", read.read_word)
    chosen = check.word("robot", "name", name)
    line = parsed("robot", "name", f"robot {chosen}")
    return Call(line, with_value(chosen), track=RobotChoice(chosen))


def trail(action: object) -> Call[None]:
    return Call(f"trail {check.choice('trail', 'action', action, TRAIL_ACTIONS)}", OK_ONLY)


def record(name: object, overwrite: bool) -> Call[Any]:
    chosen = check.word("record", "name", name)
    if chosen.lower() == "stop":
        raise ArgumentError("record", "name", "'stop' is not a name (use record_stop())")
    line = f"record {chosen}" + (
        " overwrite" if check.flag("record", "overwrite", overwrite) else ""
    )
    return Call(parsed("record", "name", line), read.read_record_folder)


def add_object(name: object, shape: object, size: object, pose: object) -> Call[None]:
    chosen = check.word("add_object", "name", name)
    kind = check.choice("add_object", "shape", shape, OBJECT_SHAPES)
    sizes = {"box": 3, "sphere": 1, "cylinder": 2}[kind]
    if isinstance(size, (int, float)) and not isinstance(size, bool):
        dims: tuple[float, ...] = (check.number("add_object", "size", size),)
    else:
        dims = check.values("add_object", "size", size)
    if len(dims) != sizes:
        raise ArgumentError("add_object", "size", f"a {kind} needs {sizes} size values")
    if min(dims) <= 0:
        raise ArgumentError("add_object", "size", f"every size must be above 0, got {dims}")
    where = pose_text("add_object", "pose", pose, (3, 6) if kind == "sphere" else (6,))
    line = f"object {chosen} {kind} {check.numbers_text(dims)} {where}"
    return Call(parsed("add_object", "name", line), OK_ONLY)


REMOVE_OBJECTS = fixed("object all remove", OK_ONLY)


def remove_object(name: object) -> Call[None]:
    chosen = check.word("remove_object", "name", name)
    return Call(parsed("remove_object", "name", f"object {chosen} remove"), OK_ONLY)


# What a client does around a call.


def speaks(verb: str) -> Callable[[F], F]:
    """Tag a client method as (one of) the way(s) to send ``verb``."""

    def tag(fn: F) -> F:
        fn.__c2rviz_verb__ = verb  # type: ignore[attr-defined]
        return fn

    return tag


def read_call(call: Call[T], reply: str) -> T:
    """``call``'s result from ``reply``: ``CommandError`` for an ``error:``, ``UnexpectedReply``
    for a reply of another shape."""
    if reply.startswith("error"):
        raise CommandError(call.line, reply)
    try:
        return call.read(reply)
    except (ValueError, TypeError):
        raise UnexpectedReply(call.line, reply) from None


def count_problem(call: Call[Any], robot: str, names: Sequence[str]) -> None:
    """Raise ``ArgumentError`` if ``call``'s joint values or indices do not fit ``names``."""
    if call.joint_count is not None:
        method, argument, given = call.joint_count
        if given != len(names):
            raise ArgumentError(
                method, argument, f"{robot} has {len(names)} joints, {given} values given"
            )
    if call.highest_index is not None:
        method, argument, index = call.highest_index
        if index >= len(names):
            raise ArgumentError(
                method,
                argument,
                f"joint {index} does not exist: {robot} has joints 0..{len(names) - 1}",
            )
