"""The data types of DataPrimitives.xsd that commands and statuses are built from.

Lengths and angles stay in the units the connection has set (``SetLengthUnits``,
``SetAngleUnits``; meter and radian by default): converting is the session's job
(see ``units``).

A ``Pose`` is a point and two directions, the tool frame's x and z axes in the base
frame. They are checked when a pose is built: every component finite and within
``±AXIS_COMPONENT_LIMIT`` (a direction needs no more, and its length is then computed
without overflow), each axis of
length at least ``MIN_AXIS_NORM`` (a direction, not necessarily of length 1: users
write ``0.7071`` for 1/sqrt(2); ``units.pose_rotation`` normalises), and the two
axes orthogonal: the cosine of the angle between them at most
``ORTHOGONALITY_TOLERANCE`` (1e-3, about 0.06 degrees from a right angle), loose enough
for axes printed with 4 significant digits, tight enough that the orientation meant
is not in doubt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

from .binding import Nested, Record, many, one, opt
from .errors import CrclValueError
from .scalars import (
    BOOLEAN,
    DOUBLE,
    FRACTION,
    JOINT_NUMBER,
    LONG,
    NON_NEGATIVE,
    POSITIVE,
    TOKEN,
    enumeration,
)

MIN_AXIS_NORM: Final = 1e-6
AXIS_COMPONENT_LIMIT: Final = 1e6
"""The largest magnitude of a direction's component (``XAxis``, ``ZAxis``)."""
POSITION_LIMIT: Final = 1e6
"""The largest magnitude of a point's coordinate in any length unit: the text port's
1000 m (``protocol.grammar.POSITION_M``) in millimeters, the finest CRCL length unit.
``units.pose_to_matrix`` holds a point to 1000 m in the connection's own unit."""
ORTHOGONALITY_TOLERANCE: Final = 1e-3


@dataclass(frozen=True)
class Point(Record):
    """A position (``PointType``) [length unit]."""

    XSI_TYPE = "PointType"
    x: float = one("X", DOUBLE)
    y: float = one("Y", DOUBLE)
    z: float = one("Z", DOUBLE)

    def _check(self) -> None:
        for label, value in zip("XYZ", (self.x, self.y, self.z)):
            if not abs(value) <= POSITION_LIMIT:
                raise CrclValueError(
                    f"{value!r} is out of range: a position lies within 1000 m of the "
                    f"origin (-{POSITION_LIMIT:g}..{POSITION_LIMIT:g} in millimeters)"
                ).within(label)


@dataclass(frozen=True)
class Vector(Record):
    """A 3D vector (``VectorType``): a direction, a velocity, a force..."""

    XSI_TYPE = "VectorType"
    i: float = one("I", DOUBLE)
    j: float = one("J", DOUBLE)
    k: float = one("K", DOUBLE)


@dataclass(frozen=True)
class PoseTolerance(Record):
    """How near a pose counts as reached: distances [length unit] along the base
    frame's X, Y, Z and angles [angle unit] of the x and z axes; each optional."""

    XSI_TYPE = "PoseToleranceType"
    x_point: float | None = opt("XPointTolerance", NON_NEGATIVE)
    y_point: float | None = opt("YPointTolerance", NON_NEGATIVE)
    z_point: float | None = opt("ZPointTolerance", NON_NEGATIVE)
    x_axis: float | None = opt("XAxisTolerance", NON_NEGATIVE)
    z_axis: float | None = opt("ZAxisTolerance", NON_NEGATIVE)


@dataclass(frozen=True)
class ParameterSetting(Record):
    """A name and a value, both text, whose meaning CRCL leaves to the device."""

    XSI_TYPE = "ParameterSettingType"
    name: str = one("ParameterName", TOKEN)
    value: str = one("ParameterValue", TOKEN)


@dataclass(frozen=True)
class TransSpeedAbsolute(Record):
    """Translational speed of the controlled point [length unit/s], > 0."""

    XSI_TYPE = "TransSpeedAbsoluteType"
    setting: float = one("Setting", POSITIVE)


@dataclass(frozen=True)
class TransSpeedRelative(Record):
    """Translational speed as a fraction (0..1) of the robot's maximum."""

    XSI_TYPE = "TransSpeedRelativeType"
    fraction: float = one("Fraction", FRACTION)


@dataclass(frozen=True)
class TransAccelAbsolute(Record):
    """Translational acceleration [length unit/s^2], > 0."""

    XSI_TYPE = "TransAccelAbsoluteType"
    setting: float = one("Setting", POSITIVE)


@dataclass(frozen=True)
class TransAccelRelative(Record):
    """Translational acceleration as a fraction (0..1) of the robot's maximum."""

    XSI_TYPE = "TransAccelRelativeType"
    fraction: float = one("Fraction", FRACTION)


@dataclass(frozen=True)
class RotSpeedAbsolute(Record):
    """Single-axis rotational speed [angle unit/s], > 0."""

    XSI_TYPE = "RotSpeedAbsoluteType"
    setting: float = one("Setting", POSITIVE)


@dataclass(frozen=True)
class RotSpeedRelative(Record):
    """Rotational speed as a fraction (0..1) of the robot's maximum."""

    XSI_TYPE = "RotSpeedRelativeType"
    fraction: float = one("Fraction", FRACTION)


@dataclass(frozen=True)
class RotAccelAbsolute(Record):
    """Single-axis rotational acceleration [angle unit/s^2], > 0."""

    XSI_TYPE = "RotAccelAbsoluteType"
    setting: float = one("Setting", POSITIVE)


@dataclass(frozen=True)
class RotAccelRelative(Record):
    """Rotational acceleration as a fraction (0..1) of the robot's maximum."""

    XSI_TYPE = "RotAccelRelativeType"
    fraction: float = one("Fraction", FRACTION)


TRANS_SPEED = Nested(TransSpeedAbsolute, TransSpeedRelative, abstract=True)
TRANS_ACCEL = Nested(TransAccelAbsolute, TransAccelRelative, abstract=True)
ROT_SPEED = Nested(RotSpeedAbsolute, RotSpeedRelative, abstract=True)
ROT_ACCEL = Nested(RotAccelAbsolute, RotAccelRelative, abstract=True)


def _unit(axis: Vector, name: str) -> tuple[float, float, float]:
    for label, value in zip("IJK", (axis.i, axis.j, axis.k)):
        if not abs(value) <= AXIS_COMPONENT_LIMIT:
            limit = f"{AXIS_COMPONENT_LIMIT:g}"
            problem = f"{value!r} is out of range: a direction's components lie within "
            raise CrclValueError(f"{problem}-{limit}..{limit}").within(label).within(name)
    norm = math.hypot(axis.i, axis.j, axis.k)
    if not norm >= MIN_AXIS_NORM:
        raise CrclValueError(
            f"{name} ({axis.i!r}, {axis.j!r}, {axis.k!r}) is not a direction: "
            f"its length must be at least {MIN_AXIS_NORM:g}"
        )
    return axis.i / norm, axis.j / norm, axis.k / norm


@dataclass(frozen=True)
class Pose(Record):
    """Where the tool is (``PoseType``): its point [length unit] and the directions of
    its x and z axes in the base frame (checked: see the module docstring)."""

    XSI_TYPE = "PoseType"
    point: Point = one("Point", Nested(Point))
    x_axis: Vector = one("XAxis", Nested(Vector))
    z_axis: Vector = one("ZAxis", Nested(Vector))

    def _check(self) -> None:
        x = _unit(self.x_axis, "XAxis")
        z = _unit(self.z_axis, "ZAxis")
        cosine = x[0] * z[0] + x[1] * z[1] + x[2] * z[2]
        if abs(cosine) > ORTHOGONALITY_TOLERANCE:
            degrees = math.degrees(math.acos(max(-1.0, min(1.0, cosine))))
            raise CrclValueError(
                f"XAxis and ZAxis are {degrees:.3g} degrees apart: they must be orthogonal "
                f"(|cos| <= {ORTHOGONALITY_TOLERANCE:g})"
            )


@dataclass(frozen=True)
class PoseAndSet(Pose):
    """A waypoint pose with its own speeds, accelerations and tolerance for the way to
    it (``PoseAndSetType``); ``coordinated``: translation and rotation end together."""

    XSI_TYPE = "PoseAndSetType"
    coordinated: bool = one("Coordinated", BOOLEAN)
    trans_speed: TransSpeedAbsolute | TransSpeedRelative | None = opt("TransSpeed", TRANS_SPEED)
    rot_speed: RotSpeedAbsolute | RotSpeedRelative | None = opt("RotSpeed", ROT_SPEED)
    trans_accel: TransAccelAbsolute | TransAccelRelative | None = opt("TransAccel", TRANS_ACCEL)
    rot_accel: RotAccelAbsolute | RotAccelRelative | None = opt("RotAccel", ROT_ACCEL)
    tolerance: PoseTolerance | None = opt("Tolerance", Nested(PoseTolerance))


POSE = Nested(Pose, PoseAndSet)
"""A pose element: ``PoseType``, or ``PoseAndSetType`` when ``xsi:type`` says so."""


@dataclass(frozen=True)
class Twist(Record):
    """Velocity of a frame: linear [length unit/s] and angular [angle unit/s]."""

    XSI_TYPE = "TwistType"
    linear_velocity: Vector = one("LinearVelocity", Nested(Vector))
    angular_velocity: Vector = one("AngularVelocity", Nested(Vector))


@dataclass(frozen=True)
class Wrench(Record):
    """Force [force unit] and moment [torque unit] on a frame."""

    XSI_TYPE = "WrenchType"
    force: Vector = one("Force", Nested(Vector))
    moment: Vector = one("Moment", Nested(Vector))


@dataclass(frozen=True)
class JointPositionTolerance(Record):
    """How near [joint's length or angle unit] joint ``joint_number`` must come."""

    XSI_TYPE = "JointPositionToleranceSettingType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    tolerance: float = one("JointPositionTolerance", NON_NEGATIVE)


@dataclass(frozen=True)
class JointPositionsTolerances(Record):
    """Per-joint position tolerances (``JointPositionsTolerancesType``), at least one."""

    XSI_TYPE = "JointPositionsTolerancesType"
    settings: tuple[JointPositionTolerance, ...] = many(
        "Setting", Nested(JointPositionTolerance), min_count=1
    )


@dataclass(frozen=True, kw_only=True)
class Guard(Record):
    """A sensor limit that aborts the command it is attached to (``GuardType``).

    ``limit_type``: OVER_MAX, UNDER_MIN, INCREASE_OVER_LIMIT or DECREASE_BEYOND_LIMIT;
    ``recheck_time_us`` [us]; ``last_check_time`` [ms since 1970].
    """

    XSI_TYPE = "GuardType"
    sensor_id: str = one("SensorID", TOKEN)
    sub_field: str | None = opt("SubField", TOKEN)
    limit_type: str = one(
        "LimitType",
        enumeration("OVER_MAX", "UNDER_MIN", "INCREASE_OVER_LIMIT", "DECREASE_BEYOND_LIMIT"),
    )
    limit_value: float = one("LimitValue", DOUBLE)
    recheck_time_us: int | None = opt("RecheckTimeMicroSeconds", LONG)
    check_count: int | None = opt("CheckCount", LONG)
    last_check_time: int | None = opt("LastCheckTime", LONG)
    last_check_value: float | None = opt("LastCheckValue", DOUBLE)
    require_trigger: bool | None = opt("RequireTrigger", BOOLEAN)
    error_on_trigger: bool | None = opt("ErrorOnTrigger", BOOLEAN)
