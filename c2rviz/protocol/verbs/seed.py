"""The seed's verbs (the first cmdinterpreter's), registered in this order: the joints
(``rand``, ``home``, ``degrees``/``radians``, ``joints``, ``move``), the markers
(``clear``, ``mark``, ``color``/``rgb``, ``marker``), the questions (``where``, ``pose``,
``limits``, ``names``, ``version``, ``help``) and the connection itself (``sleep``,
``bye``, ``quit``).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import MARKER_SHAPES, check_pose, indices, numbers, numbers_arg, one_word
from ..registry import LOOKUP, usage, verb


@verb("rand", "", "every chain joint to a random value within its limits", examples=("rand",))
@dataclass(frozen=True, slots=True)
class Rand:
    """Move every chain joint to a random value within its limits."""


@verb(
    "home",
    "",
    "every chain joint to 0 (or its nearest limit, for a joint whose range excludes 0)",
    examples=("home",),
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
    examples=("radians",),
)
@verb(
    "degrees",
    "",
    "angles of this connection, sent and received, in degrees",
    aliases=("degree",),
    parse=lambda verb, words: Units.parse(verb, words, degrees=True),
    examples=("degrees",),
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


@verb(
    "joints",
    "v0,...,vn-1",
    "set all n chain joints; exactly n values",
    aliases=("j",),
    examples=("joints 0,0.5,0,-1,0,0.6,0",),
)
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
    examples=("move 0 1", "move 0,1 0.5,-0.5"),
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


@verb("clear", "", "home, and remove every marker", examples=("clear",))
@dataclass(frozen=True, slots=True)
class Clear:
    """Home the robot and remove every marker."""


@verb(
    "mark",
    "[world] [x,y,z,roll,pitch,yaw]",
    "drop a marker at that pose in the base frame (metres; angles in the connection's unit), "
    "or with `world` in the world (cell) frame; without a pose, at the end effector",
    examples=("mark", "mark 0.5,0,1,0,90,0", "mark world 0.5,0,1,0,90,0"),
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
        check_pose(verb, (x, y, z, roll, pitch, yaw))
        return Mark((x, y, z, roll, pitch, yaw), in_world)


@verb(
    "rgb",
    "r,g,b (0..255)",
    "the same, each channel 0..255",
    parse=lambda verb, words: Color.parse(verb, words, 255.0),
    examples=("rgb 0,255,51",),
)
@verb(
    "color",
    "r,g,b (0..1)",
    "colour of this connection's next markers, each channel 0..1",
    parse=lambda verb, words: Color.parse(verb, words, 1.0),
    examples=("color 0,0.5,1",),
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
    examples=("marker cube",),
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


@verb("where", "", "reply the chain's joint values", examples=("where",))
@dataclass(frozen=True, slots=True)
class Where:
    """Ask for the chain's joint values."""


@verb(
    "pose",
    "",
    "reply the end-effector pose in the base frame: x,y,z (m), roll,pitch,yaw "
    "(the connection's unit)",
    examples=("pose",),
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
    examples=("limits", "limits all"),
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


@verb(
    "names",
    "",
    "reply the robot name and the chain's joint names in index order",
    examples=("names",),
)
@dataclass(frozen=True, slots=True)
class Names:
    """Ask for the robot name and the chain's joint names."""


@verb(
    "version",
    "",
    "reply the c2rviz version and the robot file's name and checksum: "
    "`ok c2rviz 0.2.0 robot.urdf sha256:1f3a...`",
    examples=("version",),
)
@dataclass(frozen=True, slots=True)
class Version:
    """Ask for the c2rviz version and which robot file the robot came from."""


HELP_USAGE = "help [VERB]"
"""``help``'s usage in its errors (the list shows ``help`` alone, as it always has)."""


@verb(
    "help",
    "",
    "reply the list of commands; `help VERB`: that verb's line (as the list gives it), "
    "what it does, examples, and its docs page",
    examples=("help", "help moveto"),
)
@dataclass(frozen=True, slots=True)
class Help:
    """Ask for the list of commands, or (``verb``) for one verb's line and docs page."""

    verb: str | None = None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Help:
        if not words:
            return Help()
        if len(words) > 1:
            raise BadArguments(verb, "takes one verb at most", HELP_USAGE)
        asked = words[0].lower()
        if asked not in LOOKUP:
            close = difflib.get_close_matches(asked, LOOKUP, n=2, cutoff=0.75)
            hint = " or ".join(f"'{word}'" for word in close) if len(asked) <= 40 else ""
            problem = f"no verb {shown(words[0])}" + (f": did you mean {hint}?" if hint else "")
            raise BadArguments(verb, problem, HELP_USAGE)
        return Help(LOOKUP[asked].name)

    def reply_text(self) -> str:
        """``help VERB``'s payload: ``moveto|... ARGS: SUMMARY; e.g. `EXAMPLE`, ...; see
        docs/PAGE.md`` (the examples are the verb's own, from its registry entry)."""
        assert self.verb is not None
        entry = LOOKUP[self.verb]
        names = "|".join((entry.name, *entry.aliases))
        line = f"{names} {entry.args}" if entry.args else names
        shown = ", ".join(f"`{example}`" for example in entry.examples)
        return f"{line}: {entry.summary}; {f'e.g. {shown}; ' if shown else ''}see {entry.page}"


@verb(
    "sleep",
    "seconds",
    "pause this connection for that long (others go on); the reply comes when it ends",
    examples=("sleep 0.5",),
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


@verb("bye", "", "close this connection", examples=("bye",))
@dataclass(frozen=True, slots=True)
class Bye:
    """Close this connection."""


@verb(
    "quit",
    "",
    "reply, then stop the whole program (command server and viewer), status 0",
    examples=("quit",),
)
@dataclass(frozen=True, slots=True)
class Quit:
    """Stop the whole program."""
