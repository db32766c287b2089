"""A source's units at the edge: its chain limits in degrees or radians, and the factor to SI.

Sources speak degrees or radians (metres for prismatic joints, always; CRCL may set its
length unit too); everything past the session is SI. This is the one conversion layer:
the SI size of each unit a door speaks (``DEGREE_RAD``, ``INCH_M``, ...), a chain's
per-joint factor (``joint_scale``), and ``UnitTable``, which holds, for one robot and
one unit mode, the limits in the source's units and the factor that turns its values
into SI, so the hot path (a stream of ``joints`` lines) checks and converts in C.
A door's own names for its units (CRCL's ``millimeter``, ``footPound``) stay with it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import le, mul
from typing import Final

import pinocchio as pin

from ..errors import JointLimitError, within_limit
from ..protocol import replies
from ..robot.frames import pose_se3, se3_pose
from ..robot.model import Robot

DEGREE_RAD: Final = math.pi / 180.0
"""Radians in a degree."""
MILLIMETER_M: Final = 1e-3
"""Meters in a millimeter."""
INCH_M: Final = 0.0254
"""Meters in an inch (25.4 mm exactly)."""
FOOT_M: Final = 0.3048
"""Meters in a foot."""
POUND_FORCE_N: Final = 4.4482216152605
"""Newtons in a pound-force (0.45359237 kg * 9.80665 m/s^2)."""


def joint_scale(prismatic: Sequence[bool], angle: float, length: float = 1.0) -> tuple[float, ...]:
    """Per joint, SI per source unit: ``length`` [m] for a prismatic joint, ``angle`` [rad]
    for a revolute one (SI value = source value * factor)."""
    return tuple(length if p else angle for p in prismatic)


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
        scale = joint_scale(robot.prismatic, DEGREE_RAD if degrees else 1.0)
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
        if not math.isfinite(sum(values)):
            return False
        lower, upper = self.lower, self.upper
        n = len(lower)
        if len(values) <= n:
            return all(map(le, lower, values)) and all(map(le, values, upper))
        # Several: each joint's column at once (its least and greatest value).
        return all(
            lower[j] <= min(values[j::n]) and max(values[j::n]) <= upper[j] for j in range(n)
        )

    def to_si(self, values: Sequence[float]) -> Sequence[float]:
        """``values`` (one configuration, client units) in SI, unchecked."""
        return values if self.identity else tuple(map(mul, values, self.scale))


class UnitEdge:
    """The unit boundary of a source (``session.Session`` is one): what it writes in its
    units, in SI, and back."""

    robot: Robot
    degrees: bool
    table: UnitTable
    _tables: tuple[UnitTable, UnitTable]

    def set_degrees(self, degrees: bool) -> None:
        self.degrees = degrees
        self.table = self._tables[degrees]

    @property
    def angle_scale(self) -> float:
        """SI angle = client angle * this (for poses)."""
        return DEGREE_RAD if self.degrees else 1.0

    def pose_se3(self, pose: Sequence[float]) -> pin.SE3:
        """A pose as this source writes it (x, y, z [m]; roll, pitch, yaw in its angle unit)
        as a placement."""
        x, y, z, roll, pitch, yaw = pose
        angle = self.angle_scale
        return pose_se3((x, y, z, roll * angle, pitch * angle, yaw * angle))

    def pose_text(self, placement: pin.SE3) -> str:
        """A placement as this source reads a pose: ``x,y,z,roll,pitch,yaw`` in its units."""
        x, y, z, roll, pitch, yaw = se3_pose(placement)
        angle = self.angle_scale
        return replies.numbers([x, y, z, roll / angle, pitch / angle, yaw / angle])

    def to_si(self, indices: Sequence[int], values: Sequence[float]) -> list[float]:
        """Check ``values`` (client units) against the limits; return them in SI.

        Raises:
            JointLimitError: naming the first joint out of its limits.
        """
        table = self.table
        robot = self.robot
        out = []
        for i, value in zip(indices, values):
            lower = table.lower[i]
            upper = table.upper[i]
            if lower <= value <= upper:
                out.append(value * table.scale[i])
            elif within_limit(value, lower, upper):  # a rounding error past it: at the limit
                out.append(robot.lower[i] if value < lower else robot.upper[i])
            else:
                raise JointLimitError(robot.joint_names[i], i, value, lower, upper, table.unit[i])
        return out

    def from_si(self, values: Sequence[float]) -> list[float]:
        """Chain values in this source's units."""
        return [v / s for v, s in zip(values, self.table.scale)]
