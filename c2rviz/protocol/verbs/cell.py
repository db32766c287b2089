"""Cell verbs: which robot this connection drives, and the robots of the cell."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import one_word
from ..registry import usage, verb

__all__ = ["RobotChoice", "RobotsList"]

_NAME = re.compile(r"[A-Za-z0-9_.-]+")


@verb(
    "robot",
    "[NAME]",
    "drive robot NAME of the cell from now on (units, speed and marker style stay); "
    "alone, reply the robot this connection drives",
)
@dataclass(frozen=True, slots=True)
class RobotChoice:
    """Switch this connection to robot ``name`` (None: ask which it drives)."""

    name: str | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> RobotChoice:
        if not words:
            return RobotChoice(None)
        name = one_word(verb, words)
        if _NAME.fullmatch(name) is None:
            raise BadArguments(verb, f"bad robot name {shown(name)}", usage(verb))
        return RobotChoice(name)


@verb("robots", "", "reply the cell's robots and their command ports: `ok left:31000,...`")
@dataclass(frozen=True, slots=True)
class RobotsList:
    """Ask for the robots of the cell."""
