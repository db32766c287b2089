"""The CRCL commands that change a setting: units, speeds, tolerances, parameters.

Their values are in the units in force when they arrive (a ``SetTransSpeed`` after
``SetLengthUnits millimeter`` is in mm/s).
"""

from __future__ import annotations

from dataclasses import dataclass

from .binding import Nested, many, one
from .commands import MiddleCommand
from .primitives import (
    ROT_ACCEL,
    ROT_SPEED,
    TRANS_ACCEL,
    TRANS_SPEED,
    JointPositionsTolerances,
    ParameterSetting,
    PoseTolerance,
    RotAccelAbsolute,
    RotAccelRelative,
    RotSpeedAbsolute,
    RotSpeedRelative,
    TransAccelAbsolute,
    TransAccelRelative,
    TransSpeedAbsolute,
    TransSpeedRelative,
)
from .scalars import BOOLEAN, enumeration

LENGTH_UNITS = ("meter", "millimeter", "inch")
ANGLE_UNITS = ("degree", "radian")
FORCE_UNITS = ("newton", "pound", "ounce")
TORQUE_UNITS = ("newtonMeter", "footPound")


@dataclass(frozen=True, kw_only=True)
class SetLengthUnits(MiddleCommand):
    """Lengths in later commands and statuses are in ``unit`` (one of ``LENGTH_UNITS``)."""

    XSI_TYPE = "SetLengthUnitsType"
    unit: str = one("UnitName", enumeration(*LENGTH_UNITS))


@dataclass(frozen=True, kw_only=True)
class SetAngleUnits(MiddleCommand):
    """Angles in later commands and statuses are in ``unit`` (``degree`` or ``radian``)."""

    XSI_TYPE = "SetAngleUnitsType"
    unit: str = one("UnitName", enumeration(*ANGLE_UNITS))


@dataclass(frozen=True, kw_only=True)
class SetForceUnits(MiddleCommand):
    """Forces are in ``unit`` (one of ``FORCE_UNITS``)."""

    XSI_TYPE = "SetForceUnitsType"
    unit: str = one("UnitName", enumeration(*FORCE_UNITS))


@dataclass(frozen=True, kw_only=True)
class SetTorqueUnits(MiddleCommand):
    """Torques are in ``unit`` (``newtonMeter`` or ``footPound``)."""

    XSI_TYPE = "SetTorqueUnitsType"
    unit: str = one("UnitName", enumeration(*TORQUE_UNITS))


@dataclass(frozen=True, kw_only=True)
class SetTransSpeed(MiddleCommand):
    """The tool point's speed: absolute [length unit/s] or a fraction of the maximum."""

    XSI_TYPE = "SetTransSpeedType"
    speed: TransSpeedAbsolute | TransSpeedRelative = one("TransSpeed", TRANS_SPEED)


@dataclass(frozen=True, kw_only=True)
class SetTransAccel(MiddleCommand):
    """The tool point's acceleration: absolute [length unit/s^2] or a fraction."""

    XSI_TYPE = "SetTransAccelType"
    accel: TransAccelAbsolute | TransAccelRelative = one("TransAccel", TRANS_ACCEL)


@dataclass(frozen=True, kw_only=True)
class SetRotSpeed(MiddleCommand):
    """The tool's rotational speed: absolute [angle unit/s] or a fraction."""

    XSI_TYPE = "SetRotSpeedType"
    speed: RotSpeedAbsolute | RotSpeedRelative = one("RotSpeed", ROT_SPEED)


@dataclass(frozen=True, kw_only=True)
class SetRotAccel(MiddleCommand):
    """The tool's rotational acceleration: absolute [angle unit/s^2] or a fraction."""

    XSI_TYPE = "SetRotAccelType"
    accel: RotAccelAbsolute | RotAccelRelative = one("RotAccel", ROT_ACCEL)


@dataclass(frozen=True, kw_only=True)
class SetEndPoseTolerance(MiddleCommand):
    """How near a move's end pose counts as reached."""

    XSI_TYPE = "SetEndPoseToleranceType"
    tolerance: PoseTolerance = one("Tolerance", Nested(PoseTolerance))


@dataclass(frozen=True, kw_only=True)
class SetIntermediatePoseTolerance(MiddleCommand):
    """How near each intermediate waypoint must be passed."""

    XSI_TYPE = "SetIntermediatePoseToleranceType"
    tolerance: PoseTolerance = one("Tolerance", Nested(PoseTolerance))


@dataclass(frozen=True, kw_only=True)
class SetDefaultJointPositionsTolerances(MiddleCommand):
    """Per-joint tolerances for ActuateJoints commands that give none (the schema's
    type name is spelled ``SetDefaultJointPositonsTolerancesType``)."""

    XSI_TYPE = "SetDefaultJointPositonsTolerancesType"
    joint_tolerances: JointPositionsTolerances = one(
        "JointTolerances", Nested(JointPositionsTolerances)
    )


@dataclass(frozen=True, kw_only=True)
class SetMotionCoordination(MiddleCommand):
    """Whether translation and rotation must finish together in later moves."""

    XSI_TYPE = "SetMotionCoordinationType"
    coordinated: bool = one("Coordinated", BOOLEAN)


@dataclass(frozen=True, kw_only=True)
class SetEndEffectorParameters(MiddleCommand):
    """Device-specific parameters for the end effector (at least one)."""

    XSI_TYPE = "SetEndEffectorParametersType"
    parameters: tuple[ParameterSetting, ...] = many(
        "ParameterSetting", Nested(ParameterSetting), min_count=1
    )


@dataclass(frozen=True, kw_only=True)
class SetRobotParameters(MiddleCommand):
    """Device-specific robot parameters (at least one)."""

    XSI_TYPE = "SetRobotParametersType"
    parameters: tuple[ParameterSetting, ...] = many(
        "ParameterSetting", Nested(ParameterSetting), min_count=1
    )
