"""A source's units at the edge: its chain limits in degrees or radians, and the factor to SI.

Sources speak degrees or radians (metres for prismatic joints, always); everything
past the session is SI. ``UnitTable`` holds, for one robot and one unit mode, the
limits in the source's units and the factor that turns its values into SI, so the
hot path (a stream of ``joints`` lines) checks and converts in C.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import le, mul

from ..robot.model import Robot

__all__ = ["UnitTable"]


@dataclass(frozen=True, slots=True)
class UnitTable:
    """The chain's limits in one unit mode, and the factor from it to SI.

    Attributes:
        scale: Per joint, SI value = client value * scale.
        lower, upper: Limits in client units.
        unit: Per joint, ``deg``, ``rad`` or ``m``.
        identity: Every scale is 1 (radians and metres): client values are SI as they are.
    """

    scale: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    unit: tuple[str, ...]
    identity: bool

    @classmethod
    def build(cls, robot: Robot, degrees: bool) -> UnitTable:
        angle = math.pi / 180.0 if degrees else 1.0
        scale = tuple(1.0 if p else angle for p in robot.prismatic)
        angle_unit = "deg" if degrees else "rad"
        return cls(
            scale=scale,
            lower=tuple(lo / s for lo, s in zip(robot.lower, scale)),
            upper=tuple(hi / s for hi, s in zip(robot.upper, scale)),
            unit=tuple("m" if p else angle_unit for p in robot.prismatic),
            identity=all(s == 1.0 for s in scale),
        )

    def within(self, values: Sequence[float]) -> bool:
        """Every value is finite and within its joint's limits; ``values`` may hold several
        configurations one after the other (checked in C: the hot path)."""
        return (
            math.isfinite(sum(values))
            and all(map(le, itertools.cycle(self.lower), values))
            and all(map(le, values, itertools.cycle(self.upper)))
        )

    def to_si(self, values: Sequence[float]) -> Sequence[float]:
        """``values`` (one configuration, client units) in SI, unchecked."""
        return values if self.identity else tuple(map(mul, values, self.scale))
