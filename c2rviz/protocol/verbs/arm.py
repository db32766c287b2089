"""The arm's verbs: the tool point and moves to a pose (Cartesian), which robot this
connection drives, and how its moves travel; registered in that order.

Poses are ``x,y,z,roll,pitch,yaw`` in the robot's base frame: metres, and
angles in the connection's unit, as ``pose`` and ``mark`` use them. A target
(``ik``, ``moveto``, ``movel``) may be ``x,y,z`` alone: the tool point goes
there with any orientation (what an arm of fewer than six joints can reach).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import LSPEED_M_S, TOOL_M, check_pose, numbers, numbers_arg, one_word
from ..registry import usage, verb

PoseValues = tuple[float, ...]
"""``x, y, z, roll, pitch, yaw`` (a target may be ``x, y, z`` alone: any orientation)."""


def _pose(verb: str, words: list[str]) -> PoseValues:
    values = numbers_arg(verb, words, 6)
    check_pose(verb, values)
    return values


def _target(verb: str, words: list[str]) -> PoseValues:
    values = numbers(verb, one_word(verb, words))
    if len(values) not in (3, 6):
        raise BadArguments(
            verb,
            f"needs 3 values (x,y,z) or 6 (x,y,z,roll,pitch,yaw), got {len(values)}",
            usage(verb),
        )
    check_pose(verb, values)
    return values


@verb(
    "tool",
    "[x,y,z,roll,pitch,yaw]",
    "the tool point (TCP) relative to the end-effector link, for this robot (every "
    "connection); alone, reply it; default the robot's ini `tool`, else none",
    page="docs/cartesian.md",
    examples=("tool", "tool 0,0,0.1,0,0,0"),
)
@dataclass(frozen=True, slots=True)
class Tool:
    """Set (or, with None, ask) the robot's tool offset."""

    pose: PoseValues | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Tool:
        if not words:
            return Tool(None)
        values = numbers_arg(verb, words, 6)
        check_pose(verb, values, TOOL_M)
        return Tool(values)


@verb(
    "ik",
    "x,y,z[,roll,pitch,yaw]",
    "reply `ok v0,...,vn-1`: joint values within the limits that put the tool point at "
    "that pose (`x,y,z` alone: that point, any orientation), nearest the arm's "
    "configuration; nothing moves",
    page="docs/cartesian.md",
    examples=("ik 0.5,0,0.8,0,90,0", "ik 0.5,0,0.8"),
)
@dataclass(frozen=True, slots=True)
class Ik:
    """Ask for the joint values that reach a tool pose."""

    pose: PoseValues

    @staticmethod
    def parse(verb: str, words: list[str]) -> Ik:
        return Ik(_target(verb, words))


@verb(
    "moveto",
    "x,y,z[,roll,pitch,yaw] | marker N",
    "go to that tool pose (`x,y,z` alone: that point, any orientation; or marker N, 1 the "
    "oldest) through joint space, like `joints` with the IK solution",
    page="docs/cartesian.md",
    examples=("moveto 0.5,0,0.8,0,90,0", "moveto 0.5,0,0.8", "moveto marker 3"),
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
        return MoveTo(_target(verb, words))


@verb(
    "movel",
    "x,y,z[,roll,pitch,yaw]",
    "the tool point travels a straight line to that pose (orientation by slerp; `x,y,z` "
    "alone: orientation free) at this connection's `lspeed`, slower where a joint cannot "
    "keep up; the whole line is checked first; with `motion off` only its end is shown",
    page="docs/cartesian.md",
    examples=("movel 0.5,0,0.8,0,90,0",),
)
@dataclass(frozen=True, slots=True)
class MoveL:
    """Move the tool point along a straight line to a pose."""

    pose: PoseValues

    @staticmethod
    def parse(verb: str, words: list[str]) -> MoveL:
        return MoveL(_target(verb, words))


@verb(
    "lspeed",
    "[V]",
    "this connection's `movel` tool speed, m/s (0.001..5; default 0.25); alone, reply it",
    page="docs/cartesian.md",
    examples=("lspeed", "lspeed 0.1"),
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
        low, high = LSPEED_M_S
        if not low <= value <= high:
            raise BadArguments(verb, f"{value:g} m/s is outside {low:g}..{high:g}", usage(verb))
        return LinearSpeed(value)


_NAME = re.compile(r"[A-Za-z0-9_.-]+")


@verb(
    "robot",
    "[NAME]",
    "drive robot NAME of the cell from now on (units, speed and marker style stay); "
    "alone, reply the robot this connection drives",
    page="docs/cells.md",
    examples=("robot", "robot right_arm"),
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


@verb(
    "robots",
    "",
    "reply the cell's robots and their command ports: `ok left:31000,...`",
    page="docs/cells.md",
    examples=("robots",),
)
@dataclass(frozen=True, slots=True)
class RobotsList:
    """Ask for the robots of the cell."""


MOTION_MODES = ("off", "on", "follow")


@verb(
    "motion",
    "[off|on|follow]",
    "how this connection's moves are shown: `off` at once (the default, the seed's way); "
    "`on` travel at the joints' limits, `ok` when the arm arrives; `follow` travel, `ok` "
    "at once (streamed setpoints); alone, reply the mode",
    page="docs/motion.md",
    examples=("motion", "motion on", "motion follow"),
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
    page="docs/motion.md",
    examples=("speed", "speed 10"),
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
    page="docs/motion.md",
    examples=("stop",),
)
@dataclass(frozen=True, slots=True)
class Stop:
    """Bring the arm to rest."""


@verb("wait", "", "reply when the arm is at rest", page="docs/motion.md", examples=("wait",))
@dataclass(frozen=True, slots=True)
class Wait:
    """Reply once the arm is at rest."""


@verb(
    "target",
    "",
    "reply the joint values the arm is moving to (or stands at)",
    page="docs/motion.md",
    examples=("target",),
)
@dataclass(frozen=True, slots=True)
class Target:
    """Ask for the joint values of the running move's end."""


@verb(
    "status",
    "",
    "reply `ok idle`, or `ok moving S` with the seconds left",
    page="docs/motion.md",
    examples=("status",),
)
@dataclass(frozen=True, slots=True)
class Status:
    """Ask whether the arm moves, and how long it has to go."""
