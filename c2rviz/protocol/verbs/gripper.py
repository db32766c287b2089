"""The gripper verb: open or close a robot's fingers (``grip``)."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments
from ..grammar import numbers_arg
from ..registry import usage, verb

__all__ = ["Grip"]


@verb(
    "grip",
    "[S]",
    "the gripper to S, 0 closed .. 1 open, travelling as `motion` says (a robot with no "
    "gripper gets an error); closing on a part grasps it and replies the opening where the "
    "fingers stop, opening releases it (docs/parts.md); alone, reply its opening",
)
@dataclass(frozen=True, slots=True)
class Grip:
    """Move (or, with None, ask) the gripper's opening, 0 closed .. 1 open."""

    opening: float | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Grip:
        if not words:
            return Grip(None)
        (opening,) = numbers_arg(verb, words, 1)
        if not 0.0 <= opening <= 1.0:
            raise BadArguments(verb, f"{opening:g} is outside 0..1", usage(verb))
        return Grip(opening)
