"""Questions: where, pose, limits, names, version, help."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import one_word
from ..registry import usage, verb

__all__ = ["Help", "Limits", "Names", "Pose", "Version", "Where"]


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


@verb("help", "", "reply the list of commands")
@dataclass(frozen=True, slots=True)
class Help:
    """Ask for the list of commands."""
