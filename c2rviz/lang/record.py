"""Verbs that keep and share what happens: the ``watch`` stream, the ``trail``, ``record``."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..commands import numbers_arg, one_word
from ..errors import BadArguments, shown
from ..registry import usage, verb

__all__ = [
    "MAX_WATCH_HZ",
    "RECORD_NAME",
    "TRAIL_ACTIONS",
    "Record",
    "Trail",
    "Unwatch",
    "Watch",
]

MAX_WATCH_HZ = 1000.0
"""Most ``state`` lines a second a watcher may ask for (the highest frame rate)."""
TRAIL_ACTIONS = ("on", "off", "clear")
RECORD_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9_.-]{0,99}")
"""A recording's name: an ASCII word of at most 100 characters that cannot be a path (no
separators, no leading dot)."""


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
    "record",
    "[NAME [overwrite]|stop]",
    "record what happens to this connection's robot, from every source, into NAME.txt "
    "(a command file `c2rviz-play` replays), NAME.csv (one row per frame) and NAME.html (a "
    "page that plays it, no server needed) in the recording folder; an existing NAME "
    "needs `overwrite`; `stop` ends it; alone, reply "
    "`ok recording NAME S` or `ok not recording`",
)
@dataclass(frozen=True, slots=True)
class Record:
    """Start recording ``name`` (``overwrite`` an existing one), stop (``stop``), or ask
    (both None / False)."""

    name: str | None = None
    overwrite: bool = False
    stop: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Record:
        if not words:
            return Record()
        if len(words) > 2 or (len(words) == 2 and words[1].lower() != "overwrite"):
            problem = (
                f"unknown option {shown(words[1])}; only 'overwrite'"
                if len(words) == 2
                else f"takes at most 2 arguments, got {len(words)}"
            )
            raise BadArguments(verb, problem, usage(verb))
        name = words[0]
        if name.lower() == "stop":
            if len(words) > 1:
                raise BadArguments(verb, "'stop' takes no option", usage(verb))
            return Record(stop=True)
        if RECORD_NAME.fullmatch(name) is None:
            raise BadArguments(
                verb,
                f"bad name {shown(name)}: a name is up to 100 letters, digits, '_', '-' and "
                "'.', not starting with '.' (no folders: files go into the recording folder)",
                usage(verb),
            )
        return Record(name, overwrite=len(words) == 2)
