"""Questions (``where``, ``pose``, ``limits``, ``names``, ``version``, ``help``) and the
connection itself (``sleep``, ``bye``, ``quit``), registered in that order."""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import numbers_arg, one_word
from ..registry import LOOKUP, Verb, usage, verb


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


HELP_USAGE = "help [VERB]"
"""``help``'s usage in its errors (the list shows ``help`` alone, as it always has)."""

DOCS_PAGES = {
    "joints": "docs/commands.md",
    "markers": "docs/commands.md",
    "queries": "docs/commands.md",
    "cartesian": "docs/cartesian.md",
    "cell": "docs/cells.md",
    "motion": "docs/motion.md",
    "observe": "docs/watch.md",
    "record": "docs/recording.md",  # a verb of observe.py, by name
    "workcell": "docs/workcell.md",
    "plan": "docs/planning.md",  # a verb of workcell.py, by name
    "ghost": "docs/page.md",
    "objects": "docs/commands.md",  # workcell.md shows objects, not this question
}
"""The docs page of each family of verbs (``protocol/verbs/<family>.py``), and of a verb
documented elsewhere than its family (by name); a new family's verbs get docs/commands.md,
which lists every verb."""


def docs_page(entry: Verb) -> str:
    """The docs page that tells of ``entry`` (a path from the project's root)."""
    family = entry.command.__module__.rsplit(".", 1)[-1]
    return DOCS_PAGES.get(entry.name) or DOCS_PAGES.get(family, "docs/commands.md")


@verb(
    "help",
    "",
    "reply the list of commands; `help VERB`: that verb's line (as the list gives it), "
    "what it does, and its docs page",
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
        """``help VERB``'s payload: ``moveto|... ARGS: SUMMARY; see docs/PAGE.md``."""
        assert self.verb is not None
        entry = LOOKUP[self.verb]
        names = "|".join((entry.name, *entry.aliases))
        line = f"{names} {entry.args}" if entry.args else names
        return f"{line}: {entry.summary}; see {docs_page(entry)}"


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
