"""What the scene shows and holds: the ``watch`` stream, the tool's ``trail``, the
``ghost`` and ``record`` (what happens to a robot kept in files); then the workcell:
objects around the robot, collisions now, guarded commands, and ``plan``: a
collision-free path around them to joint values or a tool pose, and its settings.
Registered in that order.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import check_pose, check_sizes, count, numbers, numbers_arg, one_word
from ..registry import usage, verb

MAX_WATCH_HZ = 1000.0
"""Most ``state`` lines a second a watcher may ask for (the highest frame rate)."""
TRAIL_ACTIONS = ("on", "off", "clear")
GHOST_ACTIONS = ("on", "off")


@verb(
    "watch",
    "[HZ]",
    "this connection also receives `state T v0,...,vn-1` lines (T: seconds since the server "
    "started; values in the connection's units) when the arm moves, at most HZ a second "
    "(default: the frame rate), and `event ...` lines (`event marker ...`, `event clear`, "
    "`event arrived`, `event stopped`, `event collision PAIRS` (or `none`, once collisions "
    "are checked), `event record-stopped ...`, `event dropped N`); "
    "replies still come one line each, in order",
    page="docs/watch.md",
    examples=("watch", "watch 20"),
)
@dataclass(frozen=True, slots=True)
class Watch:
    """Stream the arm's state to this connection, at most ``hz`` lines a second (None: the
    frame rate)."""

    hz: float | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Watch:
        if not words:
            return Watch(None)
        (hz,) = numbers_arg(verb, words, 1)
        if not 0 < hz <= MAX_WATCH_HZ:
            raise BadArguments(
                verb, f"HZ must be above 0 and at most {MAX_WATCH_HZ:g}, got {hz:g}", usage(verb)
            )
        return Watch(hz)


@verb(
    "unwatch",
    "",
    "stop this connection's `watch` stream",
    page="docs/watch.md",
    examples=("unwatch",),
)
@dataclass(frozen=True, slots=True)
class Unwatch:
    """Stop the stream."""


@verb(
    "trail",
    "[on|off|clear]",
    "a line following the tool point as the arm moves: `on` starts a fresh one, `off` "
    "removes it, `clear` empties it; alone, reply `ok on N` (its points) or `ok off`",
    page="docs/watch.md",
    examples=("trail", "trail on", "trail clear"),
)
@dataclass(frozen=True, slots=True)
class Trail:
    """Turn the trail of this connection's robot on, off, clear it, or (None) ask."""

    action: str | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Trail:
        if not words:
            return Trail(None)
        action = one_word(verb, words).lower()
        if action not in TRAIL_ACTIONS:
            raise BadArguments(
                verb, f"unknown action {shown(action)}; choose on, off or clear", usage(verb)
            )
        return Trail(action)


@verb(
    "ghost",
    "[on|off]",
    "while this connection's robot travels, the page shows its target as a translucent "
    "ghost and a `movel` or planned path as a line: `off` hides both, `on` shows them "
    "(the default); alone, reply `ok on` or `ok off`",
    page="docs/page.md",
    examples=("ghost", "ghost on"),
)
@dataclass(frozen=True, slots=True)
class Ghost:
    """Show this connection's robot's ghost and path (True), hide them, or (None) ask."""

    shown: bool | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Ghost:
        if not words:
            return Ghost(None)
        action = one_word(verb, words).lower()
        if action not in GHOST_ACTIONS:
            choose = f"unknown action {shown(action)}; choose on or off"
            raise BadArguments(verb, choose, usage(verb))
        return Ghost(action == "on")


RECORD_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9_.-]{0,99}")
"""A recording's name: an ASCII word of at most 100 characters that cannot be a path (no
separators, no leading dot)."""


@verb(
    "record",
    "[NAME [overwrite] [all]|stop]",
    "record what happens to this connection's robot, from every source, into NAME.txt "
    "(a command file `c2rviz-play` replays), NAME.csv (one row per frame), NAME.html (a "
    "page that plays it, no server needed) and NAME/ (a rosbag2 bag ROS tools open) in the "
    "recording folder; an existing NAME needs `overwrite`; each robot of a cell has its own "
    "recording, `all` records every robot at once (NAME.ROBOT.txt, .csv, .html each, one bag "
    "NAME/); `stop` ends this robot's; alone, reply `ok recording NAME S` or `ok not recording`",
    page="docs/recording.md",
    examples=("record", "record demo_1", "record demo_1 overwrite", "record stop"),
)
@dataclass(frozen=True, slots=True)
class Record:
    """Start recording ``name`` (``overwrite`` an existing one; ``every`` robot of the
    world), stop (``stop``), or ask (all None / False)."""

    name: str | None = None
    overwrite: bool = False
    stop: bool = False
    every: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Record:
        if not words:
            return Record()
        if len(words) > 3:
            raise BadArguments(verb, f"takes at most 3 arguments, got {len(words)}", usage(verb))
        name, options = words[0], [word.lower() for word in words[1:]]
        if name.lower() == "stop":
            if options:
                raise BadArguments(verb, "'stop' takes no option", usage(verb))
            return Record(stop=True)
        for k, option in enumerate(options):
            if option not in _OPTIONS:
                raise BadArguments(
                    verb,
                    f"unknown option {shown(words[1 + k])}; only 'overwrite' and 'all'",
                    usage(verb),
                )
            if option in options[:k]:
                raise BadArguments(verb, f"{option!r} given twice", usage(verb))
        if RECORD_NAME.fullmatch(name) is None:
            raise BadArguments(
                verb,
                f"bad name {shown(name)}: a name is up to 100 letters, digits, '_', '-' and "
                "'.', not starting with '.' (no folders: files go into the recording folder)",
                usage(verb),
            )
        return Record(name, overwrite="overwrite" in options, every="all" in options)


_OPTIONS = ("overwrite", "all")


_NAME = re.compile(r"[A-Za-z0-9_.-]+")
# shape -> (how many size values, whether the pose has an orientation)
_SHAPES = {"box": (3, True), "sphere": (1, False), "cylinder": (2, True)}


@dataclass(frozen=True, slots=True)
class ObjectEdit:
    """Add or replace object ``name`` (size [m]; pose x, y, z [m], roll, pitch, yaw [client's
    angle unit]) in the robot's base frame; shape ``remove`` removes it (``all``: every one)."""

    name: str
    shape: str
    size: tuple[float, ...] = ()
    pose: tuple[float, float, float, float, float, float] = (0.0,) * 6


def _parse_object(verb: str, words: list[str]) -> ObjectEdit:
    if len(words) < 2:
        raise BadArguments(verb, "needs a name and a shape (or remove)", usage(verb))
    name, kind = words[0], words[1].lower()
    if _NAME.fullmatch(name) is None or len(name) > 64:
        raise BadArguments(
            verb, f"bad object name {shown(name)}: use letters, digits, _ . -", usage(verb)
        )
    if kind == "remove":
        if len(words) != 2:
            raise BadArguments(verb, "remove takes nothing more", usage(verb))
        return ObjectEdit(name, "remove")
    if name == "all":
        raise BadArguments(verb, "'all' is not an object name (all remove clears)", usage(verb))
    if kind not in _SHAPES and len(words) > 2 and words[2].lower() in (*_SHAPES, "remove"):
        raise BadArguments(
            verb,
            f"bad object name {shown(' '.join(words[:2]))}: one word, no spaces "
            "(letters, digits, _ . -)",
            usage(verb),
        )
    if kind not in _SHAPES:
        raise BadArguments(
            verb,
            f"unknown shape {shown(kind)}; choose box, sphere or cylinder "
            "(meshes come from the ini only)",
            usage(verb),
        )
    sizes, oriented = _SHAPES[kind]
    if len(words) != 4:
        raise BadArguments(verb, f"{kind} takes a size and a pose", usage(verb))
    size = count(verb, numbers(verb, words[2]), sizes)
    check_sizes(verb, size)
    pose = numbers(verb, words[3])
    if not oriented and len(pose) == 3:
        pose = (*pose, 0.0, 0.0, 0.0)
    x, y, z, roll, pitch, yaw = count(verb, pose, 6)
    check_pose(verb, (x, y, z, roll, pitch, yaw))
    return ObjectEdit(name, kind, size, (x, y, z, roll, pitch, yaw))


verb(
    "object",
    "NAME box sx,sy,sz x,y,z,roll,pitch,yaw | NAME sphere r x,y,z | "
    "NAME cylinder r,length x,y,z,roll,pitch,yaw | NAME remove",
    "add or replace a workcell object in the base frame (metres; angles in the "
    "connection's unit; a cylinder along its z axis), or remove it; `object all remove` "
    "removes every one",
    parse=_parse_object,
    page="docs/workcell.md",
    examples=(
        "object table box 1,0.6,0.05 0.6,0,-0.03,0,0,90",
        "object ball sphere 0.1 1,2,3",
        "object table remove",
    ),
)(ObjectEdit)


@verb(
    "objects",
    "",
    "reply the workcell objects' names: `ok table,fixture` (or `ok none`)",
    examples=("objects",),
)
@dataclass(frozen=True, slots=True)
class Objects:
    """Ask for the objects' names."""


@verb(
    "collisions",
    "",
    "reply the colliding pairs now: `ok none`, or `ok link_t~table,link_b~link_s`",
    page="docs/workcell.md",
    examples=("collisions",),
)
@dataclass(frozen=True, slots=True)
class Collisions:
    """Ask which pairs collide now."""


@verb(
    "guard",
    "[on|off|plan]",
    "with `guard on` this connection's commands whose target, or any point of a move's path, "
    "collides are refused (`error: link_t would hit table at 40% of the move`); `rand` "
    "draws a free configuration (with motion, one reached along a free path); "
    "`guard plan`: joint-space moves go around what their "
    "straight path would hit instead (docs/planning.md); alone, reply it",
    page="docs/workcell.md",
    examples=("guard", "guard on", "guard plan"),
)
@dataclass(frozen=True, slots=True)
class Guard:
    """Set (or, with None, ask) whether this connection's commands are guarded, and
    (``plan``) whether joint-space moves are planned around what they would hit."""

    on: bool | None
    plan: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Guard:
        if not words:
            return Guard(None)
        word = one_word(verb, words).lower()
        if word not in ("on", "off", "plan"):
            raise BadArguments(verb, f"{shown(word)} is not on, off or plan", usage(verb))
        return Guard(word != "off", word == "plan")


PLAN_FORMS = ("joints", "pose", "timeout", "resolution")
"""What may follow ``plan``; alone it replies the last path."""


@verb(
    "plan",
    "[joints v0,...,vn-1 | pose x,y,z[,roll,pitch,yaw] | timeout [S] | resolution [A,M]]",
    "a collision-free path (around the workcell and the other robots) to joint values, or "
    "to a tool pose (position only with x,y,z), and with motion on the arm moves along it: "
    "`ok 3 waypoints 2.41 rad 3.2 s` (joint-space length, duration); alone, reply the last "
    "path's waypoints `ok q0;q1;...`; `timeout` and `resolution` set or reply this "
    "connection's search limit [s] and check steps (a joint's angle, the tool's travel [m]) "
    "(docs/planning.md)",
    page="docs/planning.md",
    examples=("plan joints 1,2,-3", "plan pose 0.5,0,1.2,0,90,0", "plan", "plan timeout 0.25"),
)
@dataclass(frozen=True, slots=True)
class Plan:
    """Plan a path (``joints``, ``pose``), set or ask a setting (``timeout``,
    ``resolution``; no values: ask), or (``show``) ask the last path's waypoints.

    Values are in the connection's units: joint values as ``joints`` takes them, a
    pose as ``moveto``, the timeout in seconds, the resolution as a joint angle and
    a tool travel in metres.
    """

    what: str
    values: tuple[float, ...] = ()

    @staticmethod
    def parse(verb: str, words: list[str]) -> Plan:
        if not words:
            return Plan("show")
        what = words[0].lower()
        if what not in PLAN_FORMS:
            raise BadArguments(
                verb, f"{shown(words[0])} is not one of {', '.join(PLAN_FORMS)}", usage(verb)
            )
        rest = words[1:]
        if len(rest) > 1:
            raise BadArguments(verb, f"{what} takes one list of values, no spaces", usage(verb))
        values = numbers(verb, rest[0]) if rest else ()
        if what in ("joints", "pose") and not values:
            raise BadArguments(verb, f"{what} needs values", usage(verb))
        if what == "pose" and len(values) not in (3, 6):
            raise BadArguments(
                verb,
                f"a pose is x,y,z or x,y,z,roll,pitch,yaw, not {len(values)} values",
                usage(verb),
            )
        if what == "timeout" and len(values) > 1:
            raise BadArguments(verb, "timeout takes one number of seconds", usage(verb))
        if what == "resolution" and len(values) not in (0, 2):
            raise BadArguments(
                verb, "resolution takes a joint step and a tool step: A,M", usage(verb)
            )
        return Plan(what, values)
