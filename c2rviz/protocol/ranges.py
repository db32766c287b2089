"""The sane range of every number the language takes that no robot limit bounds.

A value a parser accepts must also work everywhere after it: a tool offset of
1e300 m, a marker at 1e308 m (past float32 in the page) or an ``lspeed`` of
1e-320 m/s (a line that takes forever) pass a finiteness check and break later. So
each kind of number has a range here, checked by the verbs' parsers, with an error
that names it (docs/limits.md lists them).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import BadArguments
from .registry import usage

__all__ = [
    "ANGLE_LIMIT",
    "LSPEED_M_S",
    "POSITION_M",
    "SIZE_M",
    "TOOL_M",
    "check_pose",
    "check_sizes",
]

POSITION_M = 1000.0
"""A position (a pose's x, y, z, a marker's, an object's) lies within this of the origin [m]."""
TOOL_M = 10.0
"""A tool offset's x, y, z lie within this of the end-effector link [m]."""
ANGLE_LIMIT = 1e6
"""A pose's roll, pitch, yaw lie within this, in the connection's unit."""
SIZE_M = (1e-6, 100.0)
"""An object's size (edge, radius, length) [m]."""
LSPEED_M_S = (0.001, 5.0)
"""``lspeed``: the tool's straight-line speed [m/s]."""


def check_pose(verb: str, values: Sequence[float], position_m: float = POSITION_M) -> None:
    """Refuse a pose (x, y, z[, roll, pitch, yaw]) outside the sane ranges."""
    for axis, value in zip("xyz", values[:3]):
        if abs(value) > position_m:
            raise BadArguments(
                verb,
                f"{axis} = {value:g} m is outside -{position_m:g}..{position_m:g} m",
                usage(verb),
            )
    for name, value in zip(("roll", "pitch", "yaw"), values[3:]):
        if abs(value) > ANGLE_LIMIT:
            raise BadArguments(
                verb,
                f"{name} = {value:g} is outside -{ANGLE_LIMIT:g}..{ANGLE_LIMIT:g}",
                usage(verb),
            )


def check_sizes(verb: str, values: Sequence[float]) -> None:
    """Refuse an object size outside ``SIZE_M``."""
    low, high = SIZE_M
    for value in values:
        if not low <= value <= high:
            raise BadArguments(
                verb, f"size {value:g} m is outside {low:g}..{high:g} m", usage(verb)
            )
