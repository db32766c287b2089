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
