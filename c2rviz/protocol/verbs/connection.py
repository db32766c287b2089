"""The connection itself: sleep, bye, quit."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments
from ..grammar import numbers_arg
from ..registry import usage, verb

__all__ = ["Bye", "Quit", "Sleep"]


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
