"""``record``: what happens to a robot, kept in files."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..registry import usage, verb

__all__ = ["RECORD_NAME", "Record"]

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
