"""Verbs that show what happens: the ``watch`` stream, the tool's ``trail`` and the
``ghost``; and ``record``, what happens to a robot kept in files (registered last)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import numbers_arg, one_word
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


@verb("unwatch", "", "stop this connection's `watch` stream")
@dataclass(frozen=True, slots=True)
class Unwatch:
    """Stop the stream."""


@verb(
    "trail",
    "[on|off|clear]",
    "a line following the tool point as the arm moves: `on` starts a fresh one, `off` "
    "removes it, `clear` empties it; alone, reply `ok on N` (its points) or `ok off`",
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
