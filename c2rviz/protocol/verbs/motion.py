"""Motion verbs: how this connection's moves travel, and asking about the motion."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import numbers_arg, one_word
from ..registry import usage, verb

__all__ = ["MOTION_MODES", "MotionMode", "Speed", "Status", "Stop", "Target", "Wait"]

MOTION_MODES = ("off", "on", "follow")


@verb(
    "motion",
    "[off|on|follow]",
    "how this connection's moves are shown: `off` at once (the default, the seed's way); "
    "`on` travel at the joints' limits, `ok` when the arm arrives; `follow` travel, `ok` "
    "at once (streamed setpoints); alone, reply the mode",
)
@dataclass(frozen=True, slots=True)
class MotionMode:
    """Set (or, with None, ask) this connection's motion mode, one of ``MOTION_MODES``."""

    mode: str | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> MotionMode:
        if not words:
            return MotionMode(None)
        mode = one_word(verb, words).lower()
        if mode not in MOTION_MODES:
            raise BadArguments(
                verb, f"unknown mode {shown(mode)}; choose off, on or follow", usage(verb)
            )
        return MotionMode(mode)


@verb(
    "speed",
    "[P]",
    "this connection's moves at P % (1..100) of each joint's velocity limit (acceleration "
    "and jerk scaled to match); alone, reply it",
)
@dataclass(frozen=True, slots=True)
class Speed:
    """Set (or, with None, ask) this connection's speed [% of the limits]."""

    percent: float | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Speed:
        if not words:
            return Speed(None)
        (percent,) = numbers_arg(verb, words, 1)
        if not 1.0 <= percent <= 100.0:
            raise BadArguments(verb, f"{percent:g} is outside 1..100", usage(verb))
        return Speed(percent)


@verb(
    "stop",
    "",
    "the arm decelerates to rest within its limits (any connection); a connection waiting "
    "for an arrival gets `error: motion stopped by ...`; the reply comes at rest",
)
@dataclass(frozen=True, slots=True)
class Stop:
    """Bring the arm to rest."""


@verb("wait", "", "reply when the arm is at rest")
@dataclass(frozen=True, slots=True)
class Wait:
    """Reply once the arm is at rest."""


@verb("target", "", "reply the joint values the arm is moving to (or stands at)")
@dataclass(frozen=True, slots=True)
class Target:
    """Ask for the joint values of the running move's end."""


@verb("status", "", "reply `ok idle`, or `ok moving S` with the seconds left")
@dataclass(frozen=True, slots=True)
class Status:
    """Ask whether the arm moves, and how long it has to go."""
