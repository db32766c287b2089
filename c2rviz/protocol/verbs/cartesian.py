"""Cartesian verbs: the tool point, inverse kinematics, and moves to a pose.

Poses are ``x,y,z,roll,pitch,yaw`` in the robot's base frame: metres, and
angles in the connection's unit, as ``pose`` and ``mark`` use them.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments
from ..grammar import numbers_arg, one_word
from ..registry import usage, verb

__all__ = ["Ik", "LinearSpeed", "MoveL", "MoveTo", "Tool"]

PoseValues = tuple[float, float, float, float, float, float]


def _pose(verb: str, words: list[str]) -> PoseValues:
    x, y, z, roll, pitch, yaw = numbers_arg(verb, words, 6)
    return (x, y, z, roll, pitch, yaw)


@verb(
    "tool",
    "[x,y,z,roll,pitch,yaw]",
    "the tool point (TCP) relative to the end-effector link, for this robot (every "
    "connection); alone, reply it; default the robot's ini `tool`, else none",
)
@dataclass(frozen=True, slots=True)
class Tool:
    """Set (or, with None, ask) the robot's tool offset."""

    pose: PoseValues | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Tool:
        return Tool(_pose(verb, words) if words else None)


@verb(
    "ik",
    "x,y,z,roll,pitch,yaw",
    "reply `ok v0,...,vn-1`: joint values within the limits that put the tool point at "
    "that pose, nearest the arm's configuration; nothing moves",
)
@dataclass(frozen=True, slots=True)
class Ik:
    """Ask for the joint values that reach a tool pose."""

    pose: PoseValues

    @staticmethod
    def parse(verb: str, words: list[str]) -> Ik:
        return Ik(_pose(verb, words))


@verb(
    "moveto",
    "x,y,z,roll,pitch,yaw | marker N",
    "go to that tool pose (or to marker N, 1 the oldest) through joint space, like `joints` "
    "with the IK solution",
)
@dataclass(frozen=True, slots=True)
class MoveTo:
    """Go to a tool pose through joint space (``marker``: the pose of marker N, 1-based)."""

    pose: PoseValues | None
    marker: int | None = None

    @staticmethod
    def parse(verb: str, words: list[str]) -> MoveTo:
        if words and words[0].lower() == "marker":
            if len(words) != 2 or not words[1].isdigit() or not 0 < int(words[1]) < 10**6:
                raise BadArguments(verb, "marker needs a number from 1", usage(verb))
            return MoveTo(None, int(words[1]))
        return MoveTo(_pose(verb, words))


@verb(
    "movel",
    "x,y,z,roll,pitch,yaw",
    "the tool point travels a straight line to that pose (orientation by slerp) at this "
    "connection's `lspeed`, slower where a joint cannot keep up; the whole line is "
    "checked first; with `motion off` only its end is shown",
)
@dataclass(frozen=True, slots=True)
class MoveL:
    """Move the tool point along a straight line to a pose."""

    pose: PoseValues

    @staticmethod
    def parse(verb: str, words: list[str]) -> MoveL:
        return MoveL(_pose(verb, words))


@verb(
    "lspeed",
    "[V]",
    "this connection's `movel` tool speed, m/s (0 < V <= 5; default 0.25); alone, reply it",
)
@dataclass(frozen=True, slots=True)
class LinearSpeed:
    """Set (or, with None, ask) this connection's straight-line speed [m/s]."""

    m_s: float | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> LinearSpeed:
        if not words:
            return LinearSpeed(None)
        (value,) = numbers_arg(verb, [one_word(verb, words)], 1)
        if not 0.0 < value <= 5.0:
            raise BadArguments(verb, f"{value:g} m/s is outside 0..5 (0 excluded)", usage(verb))
        return LinearSpeed(value)
