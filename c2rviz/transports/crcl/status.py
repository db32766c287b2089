"""Status documents: typed ``CrclStatus`` <-> ``<CRCLStatus>`` bytes.

The classes follow CRCLStatus.xsd: their fields are its elements in its sequence order,
so ``write_status`` writes a document valid against it (checked against the schema
with ``xmlschema`` while this module was written). Parts left out: ``SensorStatuses``
and ``GuardsStatuses`` (c2rviz has no sensors) and the ``Name`` elements.

Values are in the connection's units, as the commands' are. Numbers are written with
``repr`` (exact: they read back to the same float); a status is one line of compact
XML with no trailing newline, so a client that reads one status per ``recv`` gets
exactly one document.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, cast

from .binding import Nested, Record, many, one, opt, read_record, write_record
from .documents import ROOT_ATTRIBUTES, XML_DECLARATION, parse_xml
from .errors import CrclValueError
from .primitives import (
    JointPositionsTolerances,
    ParameterSetting,
    Point,
    Pose,
    PoseTolerance,
    RotAccelAbsolute,
    RotAccelRelative,
    RotSpeedAbsolute,
    RotSpeedRelative,
    TransAccelAbsolute,
    TransAccelRelative,
    TransSpeedAbsolute,
    TransSpeedRelative,
    Twist,
    Wrench,
)
from .scalars import (
    BOOLEAN,
    COMMAND_ID,
    COUNT,
    DOUBLE,
    FRACTION,
    INT,
    JOINT_NUMBER,
    NMTOKEN,
    NON_NEGATIVE,
    STRING,
    enumeration,
)
from .setting_commands import ANGLE_UNITS, FORCE_UNITS, LENGTH_UNITS, TORQUE_UNITS

COMMAND_STATES: Final = ("CRCL_Done", "CRCL_Error", "CRCL_Working", "CRCL_Ready")
"""Done: the command completed; Error: it cannot (say why in ``description``);
Working: it is executing; Ready: no command received yet."""


@dataclass(frozen=True, kw_only=True)
class CommandStatus(Record):
    """The state of the command reported (``CommandStatusType``).

    ``command_id`` echoes the command's; ``status_id`` identifies this report (the pair
    is unique in a session); ``program_index``: InitCanon 0, first middle command 1.
    Pass text from outside through ``scalars.xml_safe_text`` before ``description``.
    """

    XSI_TYPE = "CommandStatusType"
    command_id: int = one("CommandID", COMMAND_ID)
    status_id: int = one("StatusID", COMMAND_ID)
    state: str = one("CommandState", enumeration(*COMMAND_STATES))
    description: str | None = opt("StateDescription", STRING)
    program_file: str | None = opt("ProgramFile", STRING)
    program_index: int | None = opt("ProgramIndex", COUNT)
    program_length: int | None = opt("ProgramLength", COUNT)
    override_percent: int | None = opt("OverridePercent", INT)


@dataclass(frozen=True, kw_only=True)
class JointStatus(Record):
    """One joint (numbered from 1): position [length or angle unit], torque or force,
    velocity [unit/s]; each only if reported."""

    XSI_TYPE = "JointStatusType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    position: float | None = opt("JointPosition", DOUBLE)
    torque_or_force: float | None = opt("JointTorqueOrForce", DOUBLE)
    velocity: float | None = opt("JointVelocity", DOUBLE)


@dataclass(frozen=True)
class JointStatuses(Record):
    """The reported joints (at least one; leave ``JointStatuses`` out when none is)."""

    XSI_TYPE = "JointStatusesType"
    statuses: tuple[JointStatus, ...] = many("JointStatus", Nested(JointStatus), min_count=1)

    def _check(self) -> None:
        seen: set[int] = set()
        for status in self.statuses:
            if status.joint_number in seen:
                raise CrclValueError(
                    f"joint {status.joint_number} appears twice: each joint is reported at "
                    "most once"
                )
            seen.add(status.joint_number)


@dataclass(frozen=True, kw_only=True)
class JointLimit(Record):
    """A joint's limits: positions [unit], torque or force, velocity [unit/s]."""

    XSI_TYPE = "JointLimitType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    min_position: float | None = opt("JointMinPosition", DOUBLE)
    max_position: float | None = opt("JointMaxPosition", DOUBLE)
    max_torque_or_force: float | None = opt("JointMaxTorqueOrForce", NON_NEGATIVE)
    max_velocity: float | None = opt("JointMaxVelocity", NON_NEGATIVE)


@dataclass(frozen=True, kw_only=True)
class PoseStatus(Record):
    """The tool's pose, and optionally its twist, the wrench on it and a
    robot-specific configuration text."""

    XSI_TYPE = "PoseStatusType"
    pose: Pose = one("Pose", Nested(Pose))
    twist: Twist | None = opt("Twist", Nested(Twist))
    wrench: Wrench | None = opt("Wrench", Nested(Wrench))
    configuration: str | None = opt("Configuration", STRING)


@dataclass(frozen=True, kw_only=True)
class GripperStatus(Record):
    """Any gripper's status (``GripperStatusType``, abstract)."""

    XSI_TYPE = "GripperStatusType"
    gripper_name: str = one("GripperName", NMTOKEN)
    options: tuple[ParameterSetting, ...] = many("GripperOption", Nested(ParameterSetting))
    holding_object: bool | None = opt("HoldingObject", BOOLEAN)


@dataclass(frozen=True, kw_only=True)
class ParallelGripperStatus(GripperStatus):
    """A parallel-jaw gripper: ``separation`` between the jaws [length unit]."""

    XSI_TYPE = "ParallelGripperStatusType"
    separation: float = one("Separation", NON_NEGATIVE)


@dataclass(frozen=True, kw_only=True)
class VacuumGripperStatus(GripperStatus):
    """A vacuum gripper: ``is_powered`` while the vacuum is on."""

    XSI_TYPE = "VacuumGripperStatusType"
    is_powered: bool = one("IsPowered", BOOLEAN)


@dataclass(frozen=True, kw_only=True)
class ThreeFingerGripperStatus(GripperStatus):
    """A three-finger gripper: positions 0 (closed) .. 1 (open) and forces [force unit]."""

    XSI_TYPE = "ThreeFingerGripperStatusType"
    finger1_position: float | None = opt("Finger1Position", FRACTION)
    finger2_position: float | None = opt("Finger2Position", FRACTION)
    finger3_position: float | None = opt("Finger3Position", FRACTION)
    finger1_force: float | None = opt("Finger1Force", DOUBLE)
    finger2_force: float | None = opt("Finger2Force", DOUBLE)
    finger3_force: float | None = opt("Finger3Force", DOUBLE)


GRIPPER_STATUS: Final = Nested(
    ParallelGripperStatus, VacuumGripperStatus, ThreeFingerGripperStatus, abstract=True
)


@dataclass(frozen=True, kw_only=True)
class SettingsStatus(Record):
    """The settings in force, as the Set... commands set them (``SettingsStatusType``);
    every part optional. Speeds and accelerations: the absolute or the relative form."""

    XSI_TYPE = "SettingsStatusType"
    angle_unit: str | None = opt("AngleUnitName", enumeration(*ANGLE_UNITS))
    end_effector_parameters: tuple[ParameterSetting, ...] = many(
        "EndEffectorParameterSetting", Nested(ParameterSetting)
    )
    end_effector_setting: float | None = opt("EndEffectorSetting", FRACTION)
    force_unit: str | None = opt("ForceUnitName", enumeration(*FORCE_UNITS))
    joint_limits: tuple[JointLimit, ...] = many("JointLimits", Nested(JointLimit))
    intermediate_pose_tolerance: PoseTolerance | None = opt(
        "IntermediatePoseTolerance", Nested(PoseTolerance)
    )
    length_unit: str | None = opt("LengthUnitName", enumeration(*LENGTH_UNITS))
    max_cartesian_limit: Point | None = opt("MaxCartesianLimit", Nested(Point))
    min_cartesian_limit: Point | None = opt("MinCartesianLimit", Nested(Point))
    motion_coordinated: bool | None = opt("MotionCoordinated", BOOLEAN)
    end_pose_tolerance: PoseTolerance | None = opt("EndPoseTolerance", Nested(PoseTolerance))
    robot_parameters: tuple[ParameterSetting, ...] = many(
        "RobotParameterSetting", Nested(ParameterSetting)
    )
    rot_accel_absolute: RotAccelAbsolute | None = opt("RotAccelAbsolute", Nested(RotAccelAbsolute))
    rot_accel_relative: RotAccelRelative | None = opt("RotAccelRelative", Nested(RotAccelRelative))
    rot_speed_absolute: RotSpeedAbsolute | None = opt("RotSpeedAbsolute", Nested(RotSpeedAbsolute))
    rot_speed_relative: RotSpeedRelative | None = opt("RotSpeedRelative", Nested(RotSpeedRelative))
    torque_unit: str | None = opt("TorqueUnitName", enumeration(*TORQUE_UNITS))
    trans_accel_absolute: TransAccelAbsolute | None = opt(
        "TransAccelAbsolute", Nested(TransAccelAbsolute)
    )
    trans_accel_relative: TransAccelRelative | None = opt(
        "TransAccelRelative", Nested(TransAccelRelative)
    )
    trans_speed_absolute: TransSpeedAbsolute | None = opt(
        "TransSpeedAbsolute", Nested(TransSpeedAbsolute)
    )
    trans_speed_relative: TransSpeedRelative | None = opt(
        "TransSpeedRelative", Nested(TransSpeedRelative)
    )
    joint_tolerances: JointPositionsTolerances | None = opt(
        "JointTolerances", Nested(JointPositionsTolerances)
    )


@dataclass(frozen=True, kw_only=True)
class CrclStatus(Record):
    """A whole status (``CRCLStatusType``): the command's state and the optional parts."""

    XSI_TYPE = "CRCLStatusType"
    command_status: CommandStatus = one("CommandStatus", Nested(CommandStatus))
    joint_statuses: JointStatuses | None = opt("JointStatuses", Nested(JointStatuses))
    pose_status: PoseStatus | None = opt("PoseStatus", Nested(PoseStatus))
    gripper_status: GripperStatus | None = opt("GripperStatus", GRIPPER_STATUS)
    settings_status: SettingsStatus | None = opt("SettingsStatus", Nested(SettingsStatus))


_STATUS: Final = Nested(CrclStatus)


def write_status(status: CrclStatus) -> bytes:
    """The ``<CRCLStatus>`` document: declaration and compact XML, no trailing newline."""
    if not isinstance(status, CrclStatus):
        raise TypeError(f"not a CrclStatus: {status!r}")
    out = [XML_DECLARATION]
    write_record(status, "CRCLStatus", out, None, ROOT_ATTRIBUTES)
    return "".join(out).encode()


def parse_status(doc: bytes) -> CrclStatus:
    """The ``CrclStatus`` of one ``<CRCLStatus>`` document (for clients and the player).

    Raises:
        CrclError: As ``documents.parse_instance``.
    """
    return cast(CrclStatus, read_record(_STATUS, parse_xml(doc, ("CRCLStatus",))))
