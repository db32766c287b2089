"""The command language: one text line in, one frozen command out.

A pure parser: no sockets, no robot, no state. ``parse_line`` knows the shape
of every command (how many numbers, which words) but not the robot, so joint
counts, index ranges and limits are checked later by the session. Numbers are
returned exactly as written, in the client's units; the session converts.

Every verb is one entry of ``registry.VERBS``, declared here on its command
class with ``@verb``; its handler lives on the session side (``handlers``).

Grammar (see the README for the full table):

- verbs are case-insensitive; ``#`` starts a comment; blank lines are ``None``;
- spaces and tabs separate words; spaces around commas are allowed;
- numbers are ASCII decimals (``-1``, ``2.5``, ``.5``, ``1e-3``); ``nan``,
  ``inf``, hex, underscores and non-ASCII digits are rejected, and so is a
  value that overflows to infinity (``1e309``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .errors import BadArguments, LineError, UnknownCommand, shown
from .registry import LOOKUP, VERBS, usage, verb

__all__ = [
    "MARKER_SHAPES",
    "USAGE",
    "VERBS",
    "Bye",
    "Clear",
    "Color",
    "Command",
    "ForeignProtocol",
    "Help",
    "Home",
    "Joints",
    "Mark",
    "MarkerShape",
    "Move",
    "Limits",
    "Names",
    "Pose",
    "Quit",
    "Rand",
    "Sleep",
    "Units",
    "Version",
    "Where",
    "parse_line",
]

MARKER_SHAPES = ("sphere", "cube", "arrow", "cylinder")


class ForeignProtocol(LineError):
    """A line that is plainly another protocol (an HTTP request) hitting our port."""

    def __init__(self) -> None:
        super().__init__(
            "this is the c2rviz command port (one text command per line), not HTTP; "
            "open the viewer's address in a browser instead"
        )


# The grammar's pieces, shared by every verb's parser.

# Unambiguous (digits, then an optional fraction): a regex that could split a run of digits
# two ways backtracks quadratically, and one 8 KiB line held the event loop for 3 s.
_NUMBER = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_NUMBER_RE = re.compile(_NUMBER)
_NUMBER_CHARS_RE = re.compile(r"[0-9.,eE+-]*")
_INDEX_RE = re.compile(r"[0-9]+")
_INDEX_LIST_RE = re.compile(r"[0-9]+(?:,[0-9]+)*")
_AROUND_COMMA_RE = re.compile(r"[ \t]*,[ \t]*")
# An HTTP request line (a method word, any case, then whitespace and "/"; or anything
# ending in " HTTP/1.1": HTTP/0.9's "GET /", "OPTIONS *", "CONNECT host:443 HTTP/1.1"),
# or one of the headers every HTTP client sends. Only these: a typo such as "where:"
# stays an unknown command, not a disconnect. Tried on the stripped line, and only when
# its first word is no verb.
_HTTP_RE = re.compile(
    r"(?i:get|post|put|delete|head|options|patch|connect|trace)\s+/.*"
    r"|.*\sHTTP/[0-9]\.[0-9]"
    r"|(?i:host|user-agent|accept|accept-encoding|accept-language|connection|content-length"
    r"|content-type|cookie|upgrade|origin|referer|sec-websocket-key):.*"
)
_MAX_INDEX_DIGITS = 9


def numbers(verb: str, text: str) -> tuple[float, ...]:
    """Parse a comma list of ASCII decimals; reject malformed and non-finite values."""
    values = None
    if _NUMBER_CHARS_RE.fullmatch(text) is not None:
        # Spelled with these characters alone, a value float() accepts is one _NUMBER
        # matches and back (no nan, inf, underscore or space can be written with them;
        # tests/test_parser.py tries every string of up to 6 of them), so float() does
        # the checking: 3x cheaper than the list regex on a stream of `joints` lines.
        try:
            values = tuple(map(float, text.split(",")))
        except ValueError:
            values = None
    if values is None:
        for item in text.split(","):
            if _NUMBER_RE.fullmatch(item) is None:
                problem = "empty value in list" if not item else f"bad number {shown(item)}"
                raise BadArguments(verb, problem, usage(verb))
        values = tuple(map(float, text.split(",")))
    # A sum is finite only if every value is (none is nan): one C call in the usual case.
    if not math.isfinite(sum(values)) and not all(map(math.isfinite, values)):
        big = next(item for item in text.split(",") if not math.isfinite(float(item)))
        raise BadArguments(verb, f"value {shown(big)} is not a finite number", usage(verb))
    return values


def indices(verb: str, text: str) -> tuple[int, ...]:
    """Parse a comma list of joint indices (ASCII digits, no sign)."""
    if _INDEX_LIST_RE.fullmatch(text) is None:
        for item in text.split(","):
            if _INDEX_RE.fullmatch(item) is None:
                problem = "empty index in list" if not item else f"bad joint index {shown(item)}"
                raise BadArguments(verb, problem, usage(verb))
    items = text.split(",")
    for item in items:
        if len(item) > _MAX_INDEX_DIGITS:
            raise BadArguments(verb, f"joint index {shown(item, 12)} is too large", usage(verb))
    return tuple(map(int, items))


def count(verb: str, values: tuple[float, ...], needed: int) -> tuple[float, ...]:
    """``values`` if there are ``needed`` of them, else ``BadArguments``."""
    if len(values) != needed:
        raise BadArguments(verb, f"needs {needed} values, got {len(values)}", usage(verb))
    return values


def one_word(verb: str, words: list[str]) -> str:
    """The single argument of ``verb``, else ``BadArguments``."""
    if len(words) != 1:
        problem = "needs an argument" if not words else f"takes 1 argument, got {len(words)}"
        raise BadArguments(verb, problem, usage(verb))
    return words[0]


def numbers_arg(verb: str, words: list[str], needed: int) -> tuple[float, ...]:
    """The single argument of ``verb`` as exactly ``needed`` numbers."""
    return count(verb, numbers(verb, one_word(verb, words)), needed)


# The verbs, in the order `help` lists them.


@verb("rand", "", "every chain joint to a random value within its limits")
@dataclass(frozen=True, slots=True)
class Rand:
    """Move every chain joint to a random value within its limits."""


@verb(
    "home", "", "every chain joint to 0 (or its nearest limit, for a joint whose range excludes 0)"
)
@dataclass(frozen=True, slots=True)
class Home:
    """Move every chain joint to zero (or the nearest limit where zero is outside)."""


@verb(
    "radians",
    "",
    "angles of this connection, sent and received, in radians (the default)",
    aliases=("radian",),
    parse=lambda verb, words: Units.parse(verb, words, degrees=False),
)
@verb(
    "degrees",
    "",
    "angles of this connection, sent and received, in degrees",
    aliases=("degree",),
    parse=lambda verb, words: Units.parse(verb, words, degrees=True),
)
@dataclass(frozen=True, slots=True)
class Units:
    """Switch this connection's angle unit (``degrees=True``) or back to radians."""

    degrees: bool

    @staticmethod
    def parse(verb: str, words: list[str], degrees: bool) -> Units:
        if words:
            raise BadArguments(verb, "takes no arguments", usage(verb))
        return _UNITS[degrees]


_UNITS = (Units(degrees=False), Units(degrees=True))


@verb("joints", "v0,...,vn-1", "set all n chain joints; exactly n values", aliases=("j",))
@dataclass(frozen=True, slots=True)
class Joints:
    """Set all chain joints, in the client's units."""

    values: tuple[float, ...]

    @staticmethod
    def parse(verb: str, words: list[str]) -> Joints:
        return Joints(numbers(verb, one_word(verb, words)))


@verb(
    "move",
    "i[,j,...] vi[,vj,...]",
    "set the listed joints; as many values as indices, each index once",
)
@dataclass(frozen=True, slots=True)
class Move:
    """Set the joints at ``indices`` to ``values`` (client's units)."""

    indices: tuple[int, ...]
    values: tuple[float, ...]

    @staticmethod
    def parse(verb: str, words: list[str]) -> Move:
        if len(words) != 2:
            raise BadArguments(verb, f"takes 2 arguments, got {len(words)}", usage(verb))
        chosen = indices(verb, words[0])
        values = numbers(verb, words[1])
        if len(chosen) != len(values):
            raise BadArguments(verb, f"{len(chosen)} indices but {len(values)} values", usage(verb))
        if len(set(chosen)) != len(chosen):
            twice = next(i for i in chosen if chosen.count(i) > 1)
            raise BadArguments(verb, f"joint {twice} is given twice", usage(verb))
        return Move(chosen, values)


@verb("clear", "", "home, and remove every marker")
@dataclass(frozen=True, slots=True)
class Clear:
    """Home the robot and remove every marker."""


@verb(
    "mark",
    "[world] [x,y,z,roll,pitch,yaw]",
    "drop a marker at that pose in the base frame (metres; angles in the connection's unit), "
    "or with `world` in the world (cell) frame; without a pose, at the end effector",
)
@dataclass(frozen=True, slots=True)
class Mark:
    """Drop a marker at ``pose`` (x, y, z [m], roll, pitch, yaw [client's units]).

    ``pose`` is None for a marker at the current end-effector pose; ``in_world``
    puts it in the world (cell) frame instead of the robot's base frame.
    """

    pose: tuple[float, float, float, float, float, float] | None
    in_world: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Mark:
        in_world = bool(words) and words[0].lower() == "world"
        if in_world:
            words = words[1:]
            if not words:
                raise BadArguments(verb, "world needs a pose", usage(verb))
        if not words:
            return Mark(None)
        x, y, z, roll, pitch, yaw = numbers_arg(verb, words, 6)
        return Mark((x, y, z, roll, pitch, yaw), in_world)


@verb(
    "rgb",
    "r,g,b (0..255)",
    "the same, each channel 0..255",
    parse=lambda verb, words: Color.parse(verb, words, 255.0),
)
@verb(
    "color",
    "r,g,b (0..1)",
    "colour of this connection's next markers, each channel 0..1",
    parse=lambda verb, words: Color.parse(verb, words, 1.0),
)
@dataclass(frozen=True, slots=True)
class Color:
    """Colour of this connection's next markers, each channel 0..1."""

    rgb: tuple[float, float, float]

    @staticmethod
    def parse(verb: str, words: list[str], top: float) -> Color:
        r, g, b = numbers_arg(verb, words, 3)
        for channel in (r, g, b):
            if not 0.0 <= channel <= top:
                raise BadArguments(verb, f"channel {channel:g} is outside 0..{top:g}", usage(verb))
        return Color((r / top, g / top, b / top))


@verb(
    "marker",
    "|".join(MARKER_SHAPES),
    "shape of this connection's next markers (default a small red sphere)",
)
@dataclass(frozen=True, slots=True)
class MarkerShape:
    """Shape of this connection's next markers, one of ``MARKER_SHAPES``."""

    shape: str

    @staticmethod
    def parse(verb: str, words: list[str]) -> MarkerShape:
        shape = one_word(verb, words).lower()
        if shape not in MARKER_SHAPES:
            raise BadArguments(verb, f"unknown shape {shown(shape)}", usage(verb))
        return MarkerShape(shape)


@verb("where", "", "reply the chain's joint values")
@dataclass(frozen=True, slots=True)
class Where:
    """Ask for the chain's joint values."""


@verb(
    "pose",
    "",
    "reply the end-effector pose in the base frame: x,y,z (m), roll,pitch,yaw "
    "(the connection's unit)",
)
@dataclass(frozen=True, slots=True)
class Pose:
    """Ask for the end-effector pose in the base frame."""


@verb(
    "limits",
    "[all]",
    "reply each chain joint's limits and unit, in index order: `ok -109.4..109.4 deg,...`; "
    "`limits all` adds each joint's velocity, acceleration and jerk limits: "
    "`ok -109.4..109.4 deg v=130 a=260 j=1300,...` (per s, s^2, s^3)",
)
@dataclass(frozen=True, slots=True)
class Limits:
    """Ask for each chain joint's limits and unit (``all``: and its motion limits)."""

    all: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Limits:
        if not words:
            return Limits()
        if one_word(verb, words).lower() != "all":
            raise BadArguments(verb, f"unknown argument {shown(words[0])}", usage(verb))
        return Limits(all=True)


@verb("names", "", "reply the robot name and the chain's joint names in index order")
@dataclass(frozen=True, slots=True)
class Names:
    """Ask for the robot name and the chain's joint names."""


@verb(
    "version",
    "",
    "reply the c2rviz version and the robot file's name and checksum: "
    "`ok c2rviz 0.2.0 robot.urdf sha256:1f3a...`",
)
@dataclass(frozen=True, slots=True)
class Version:
    """Ask for the c2rviz version and which robot file the robot came from."""


@verb("help", "", "reply the list of commands")
@dataclass(frozen=True, slots=True)
class Help:
    """Ask for the list of commands."""


@verb(
    "sleep",
    "seconds",
    "pause this connection for that long (others go on); the reply comes when it ends",
)
@dataclass(frozen=True, slots=True)
class Sleep:
    """Pause this connection for ``seconds`` [s]."""

    seconds: float

    @staticmethod
    def parse(verb: str, words: list[str]) -> Sleep:
        (seconds,) = numbers_arg(verb, words, 1)
        if seconds < 0:
            raise BadArguments(verb, f"seconds must be >= 0, got {seconds:g}", usage(verb))
        return Sleep(seconds)


@verb("bye", "", "close this connection")
@dataclass(frozen=True, slots=True)
class Bye:
    """Close this connection."""


@verb("quit", "", "reply, then stop the whole program (command server and viewer), status 0")
@dataclass(frozen=True, slots=True)
class Quit:
    """Stop the whole program."""


Command = object
"""Any command: an instance of a class registered with ``@verb``."""

USAGE: dict[str, str] = {word: v.usage for word, v in LOOKUP.items()}
"""Usage of every verb and alias (the REPL completes these)."""


def _clean(line: str) -> str:
    """Return ``line`` with tabs as spaces, or raise for any other control or non-ASCII."""
    line = line.replace("\t", " ")
    if line.isascii() and line.isprintable():
        return line
    for column, char in enumerate(line, start=1):
        if not (char.isascii() and char.isprintable()):
            raise LineError(
                f"character {ascii(char)} at column {column} is not allowed: "
                "commands are plain ASCII text"
            )
    return line  # pragma: no cover - the loop always finds the character


def parse_line(line: str) -> object | None:
    """Parse one line of the command language.

    Args:
        line: One line, with or without its trailing ``\\n`` / ``\\r\\n``.

    Returns:
        The command, or None for a blank or comment-only line.

    Raises:
        C2rvizError: ``UnknownCommand``, ``BadArguments``, ``LineError`` (or its
            ``ForeignProtocol``), each with a message for the user.
    """
    if "#" in line:
        line = line[: line.index("#")]
    line = line.rstrip("\r\n")
    if not (line.isascii() and line.isprintable()):
        line = _clean(line)
    words = line.split()
    if not words:
        return None
    entry = LOOKUP.get(words[0].lower())
    if entry is None:
        if _HTTP_RE.fullmatch(line.strip()):
            raise ForeignProtocol()
        raise UnknownCommand(words[0])
    args = words[1:]
    if len(args) > 1 and "," in line:
        args = _AROUND_COMMA_RE.sub(",", " ".join(args)).split()
    return entry.parse(entry.name, args)


# The verbs beyond the seed's, one module per concern (they use the pieces above).
from .lang import cartesian as _cartesian  # noqa: E402, F401
from .lang import cell as _cell  # noqa: E402, F401
from .lang import motion as _motion  # noqa: E402, F401
from .lang import record as _record  # noqa: E402, F401
from .lang import workcell as _workcell  # noqa: E402, F401
