"""The joints: rand, home, degrees/radians, joints, move (the seed's own verbs)."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments
from ..grammar import indices, numbers, one_word
from ..registry import usage, verb

__all__ = ["Home", "Joints", "Move", "Rand", "Units"]


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
