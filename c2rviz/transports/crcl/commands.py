"""The CRCL commands: their root, the session's own, and those that move or work the tool.

Every command is a frozen dataclass built with keywords, e.g.
``Dwell(command_id=5, seconds=2.5)``; ``command_id`` is the ``CommandID`` its
statuses echo (an integer >= 0), ``name`` the optional ``Name`` and ``guards`` the
sensor ``Guard`` elements any command may carry. Here: the root and the commands about
the session itself; those that move the arm, stop it or make it wait (positions in the
connection's length and angle units, see ``primitives``); those for the end effector,
tool changer, grippers, sensors and the robot-parameter reports. The commands that
change a setting live in ``setting_commands``; ``documents`` lists them all.
"""

from __future__ import annotations

from dataclasses import dataclass

from .binding import Nested, Record, many, one, opt
from .errors import CrclValueError
from .primitives import (
    POSE,
    Guard,
    JointPositionsTolerances,
    ParameterSetting,
    Point,
    Pose,
    PoseAndSet,
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
    POSITIVE,
    STRING,
    TOKEN,
    enumeration,
)


@dataclass(frozen=True, kw_only=True)
class Command(Record):
    """Any CRCL command (``CRCLCommandType``, abstract)."""

    XSI_TYPE = "CRCLCommandType"
    name: str | None = opt("Name", STRING)
    command_id: int = one("CommandID", COMMAND_ID)
    guards: tuple[Guard, ...] = many("Guard", Nested(Guard))


@dataclass(frozen=True, kw_only=True)
class MiddleCommand(Command):
    """Any command but InitCanon and EndCanon (``MiddleCommandType``, abstract)."""

    XSI_TYPE = "MiddleCommandType"


@dataclass(frozen=True, kw_only=True)
class InitCanon(Command):
    """Get ready to execute commands; nothing else is executed before it."""

    XSI_TYPE = "InitCanonType"


@dataclass(frozen=True, kw_only=True)
class EndCanon(Command):
    """Execute nothing but InitCanon from now on."""

    XSI_TYPE = "EndCanonType"


@dataclass(frozen=True, kw_only=True)
class GetStatus(MiddleCommand):
    """Report a status now."""

    XSI_TYPE = "GetStatusType"


@dataclass(frozen=True, kw_only=True)
class Message(MiddleCommand):
    """Show ``message`` to the operator."""

    XSI_TYPE = "MessageType"
    message: str = one("Message", STRING)


@dataclass(frozen=True, kw_only=True)
class RunProgram(MiddleCommand):
    """Run ``program_text``, a program in the controller's own (non-CRCL) language."""

    XSI_TYPE = "RunProgramType"
    program_text: str = one("ProgramText", STRING)


@dataclass(frozen=True, kw_only=True)
class ConfigureJointReport(Record):
    """What a status reports about joint ``joint_number`` (numbered from 1)."""

    XSI_TYPE = "ConfigureJointReportType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    report_position: bool = one("ReportPosition", BOOLEAN)
    report_torque_or_force: bool = one("ReportTorqueOrForce", BOOLEAN)
    report_velocity: bool = one("ReportVelocity", BOOLEAN)


@dataclass(frozen=True, kw_only=True)
class ConfigureJointReports(MiddleCommand):
    """Change joint reporting: ``reset_all`` first turns every joint's off; then each
    report (joint numbers increasing, none twice) sets one joint's."""

    XSI_TYPE = "ConfigureJointReportsType"
    reset_all: bool = one("ResetAll", BOOLEAN)
    reports: tuple[ConfigureJointReport, ...] = many(
        "ConfigureJointReport", Nested(ConfigureJointReport)
    )

    def _check(self) -> None:
        numbers = [report.joint_number for report in self.reports]
        for before, after in zip(numbers, numbers[1:]):
            if before >= after:
                raise CrclValueError(
                    f"joint {after} comes after joint {before}: joint numbers must be "
                    "increasing, each joint at most once"
                )


@dataclass(frozen=True, kw_only=True)
class ConfigureStatusReport(MiddleCommand):
    """Which parts a status carries."""

    XSI_TYPE = "ConfigureStatusReportType"
    report_joint_statuses: bool = one("ReportJointStatuses", BOOLEAN)
    report_pose_status: bool = one("ReportPoseStatus", BOOLEAN)
    report_gripper_status: bool = one("ReportGripperStatus", BOOLEAN)
    report_settings_status: bool = one("ReportSettingsStatus", BOOLEAN)
    report_sensors_status: bool = one("ReportSensorsStatus", BOOLEAN)
    report_guards_status: bool = one("ReportGuardsStatus", BOOLEAN)


@dataclass(frozen=True, kw_only=True)
class LoopBlockStart(MiddleCommand):
    """Start of a block of a program to repeat, ended by the LoopBlockEnd of the same name."""

    XSI_TYPE = "LoopBlockStartType"
    loop_name: str = one("LoopName", STRING)


@dataclass(frozen=True, kw_only=True)
class LoopBlockEnd(MiddleCommand):
    """End of the loop block ``loop_name``, repeated ``max_count`` times (>= 0)."""

    XSI_TYPE = "LoopBlockEndType"
    loop_name: str = one("LoopName", STRING)
    max_count: int = one("MaxCount", COUNT)


STOP_CONDITIONS = ("Immediate", "Fast", "Normal")
"""How a StopMotion stops: drives off at once / fast controlled stop / normal ramp."""


# The commands that move the arm, stop it or make it wait.


@dataclass(frozen=True, kw_only=True)
class MoveTo(MiddleCommand):
    """Move the tool to ``end_position``: along a straight line if ``move_straight``,
    else along any convenient way (through joint space)."""

    XSI_TYPE = "MoveToType"
    move_straight: bool = one("MoveStraight", BOOLEAN)
    end_position: Pose | PoseAndSet = one("EndPosition", POSE)


@dataclass(frozen=True, kw_only=True)
class MoveThroughTo(MiddleCommand):
    """Move through each waypoint to the last; ``num_positions`` must equal their count
    (at least 2); ``move_straight`` as for MoveTo, for every segment."""

    XSI_TYPE = "MoveThroughToType"
    move_straight: bool = one("MoveStraight", BOOLEAN)
    waypoints: tuple[Pose | PoseAndSet, ...] = many("Waypoint", POSE, min_count=2)
    num_positions: int = one("NumPositions", INT)

    def _check(self) -> None:
        if self.num_positions != len(self.waypoints):
            raise CrclValueError(
                f"NumPositions is {self.num_positions} but there are "
                f"{len(self.waypoints)} Waypoint elements: they must agree"
            )


@dataclass(frozen=True, kw_only=True)
class MoveScrew(MiddleCommand):
    """Screw motion: optionally go to ``start_position`` and advance
    ``axial_distance_free`` [length unit], then turn by ``turn`` [angle unit] while
    advancing ``axial_distance_screw`` [length unit], around the tool axis or, if
    given, around a parallel axis through ``axis_point``."""

    XSI_TYPE = "MoveScrewType"
    start_position: Pose | PoseAndSet | None = opt("StartPosition", POSE)
    axis_point: Point | None = opt("AxisPoint", Nested(Point))
    axial_distance_free: float | None = opt("AxialDistanceFree", DOUBLE)
    axial_distance_screw: float = one("AxialDistanceScrew", DOUBLE)
    turn: float = one("Turn", DOUBLE)


@dataclass(frozen=True, kw_only=True)
class JointSpeedAccel(Record):
    """Speed [unit/s] and acceleration [unit/s^2] for a joint's move; each > 0, optional."""

    XSI_TYPE = "JointSpeedAccelType"
    speed: float | None = opt("JointSpeed", POSITIVE)
    accel: float | None = opt("JointAccel", POSITIVE)


@dataclass(frozen=True, kw_only=True)
class JointForceTorque(Record):
    """Force or torque [force or torque unit] and its rate of change [unit/s] for a joint."""

    XSI_TYPE = "JointForceTorqueType"
    setting: float | None = opt("Setting", DOUBLE)
    change_rate: float | None = opt("ChangeRate", DOUBLE)


@dataclass(frozen=True, kw_only=True)
class ActuateJoint(Record):
    """Move joint ``joint_number`` (from 1) to ``position`` [joint's length or angle
    unit], with ``details`` saying how (speed/accel or force/torque)."""

    XSI_TYPE = "ActuateJointType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    position: float = one("JointPosition", DOUBLE)
    details: JointSpeedAccel | JointForceTorque = one(
        "JointDetails", Nested(JointSpeedAccel, JointForceTorque, abstract=True)
    )


@dataclass(frozen=True, kw_only=True)
class ActuateJoints(MiddleCommand):
    """Move some joints (each at most once); the others keep their current setting."""

    XSI_TYPE = "ActuateJointsType"
    joints: tuple[ActuateJoint, ...] = many("ActuateJoint", Nested(ActuateJoint), min_count=1)
    joint_tolerances: JointPositionsTolerances | None = opt(
        "JointTolerances", Nested(JointPositionsTolerances)
    )

    def _check(self) -> None:
        seen: set[int] = set()
        for joint in self.joints:
            if joint.joint_number in seen:
                raise CrclValueError(f"joint {joint.joint_number} appears more than once")
            seen.add(joint.joint_number)


@dataclass(frozen=True, kw_only=True)
class StopMotion(MiddleCommand):
    """Stop the arm; ``condition`` is one of ``STOP_CONDITIONS``."""

    XSI_TYPE = "StopMotionType"
    condition: str = one("StopCondition", enumeration(*STOP_CONDITIONS))


@dataclass(frozen=True, kw_only=True)
class Dwell(MiddleCommand):
    """Wait ``seconds`` [s] (>= 0) before the next command."""

    XSI_TYPE = "DwellType"
    seconds: float = one("DwellTime", NON_NEGATIVE)


# The commands for the end effector, tool changer, grippers, sensors and parameter reports.


@dataclass(frozen=True, kw_only=True)
class SetEndEffector(MiddleCommand):
    """Set the end effector to ``setting``, a fraction 0..1: for a gripper 0 is
    closed and 1 fully open; for an on/off tool 0 is off and anything above is on."""

    XSI_TYPE = "SetEndEffectorType"
    setting: float = one("Setting", FRACTION)


@dataclass(frozen=True, kw_only=True)
class OpenToolChanger(MiddleCommand):
    """Release the mounted end effector (the controlled point changes)."""

    XSI_TYPE = "OpenToolChangerType"


@dataclass(frozen=True, kw_only=True)
class CloseToolChanger(MiddleCommand):
    """Mount the end effector the tool changer is at (the controlled point changes)."""

    XSI_TYPE = "CloseToolChangerType"


@dataclass(frozen=True, kw_only=True)
class EnableGripper(MiddleCommand):
    """Enable the gripper ``gripper_name``, with device-specific options."""

    XSI_TYPE = "EnableGripperType"
    gripper_name: str = one("GripperName", NMTOKEN)
    options: tuple[ParameterSetting, ...] = many("GripperOption", Nested(ParameterSetting))


@dataclass(frozen=True, kw_only=True)
class DisableGripper(MiddleCommand):
    """Disable the gripper ``gripper_name``."""

    XSI_TYPE = "DisableGripperType"
    gripper_name: str = one("GripperName", NMTOKEN)


@dataclass(frozen=True, kw_only=True)
class EnableSensor(MiddleCommand):
    """Start reporting the sensor ``sensor_id``, with device-specific options."""

    XSI_TYPE = "EnableSensorType"
    sensor_id: str = one("SensorID", TOKEN)
    options: tuple[ParameterSetting, ...] = many("SensorOption", Nested(ParameterSetting))


@dataclass(frozen=True, kw_only=True)
class DisableSensor(MiddleCommand):
    """Stop reporting the sensor ``sensor_id``."""

    XSI_TYPE = "DisableSensorType"
    sensor_id: str = one("SensorID", TOKEN)


@dataclass(frozen=True, kw_only=True)
class EnableRobotParameterStatus(MiddleCommand):
    """Start reporting the robot parameter ``parameter_name`` in statuses."""

    XSI_TYPE = "EnableRobotParameterStatusType"
    parameter_name: str = one("RobotParameterName", TOKEN)


@dataclass(frozen=True, kw_only=True)
class DisableRobotParameterStatus(MiddleCommand):
    """Stop reporting the robot parameter ``parameter_name``."""

    XSI_TYPE = "DisableRobotParameterStatusType"
    parameter_name: str = one("RobotParameterName", TOKEN)
