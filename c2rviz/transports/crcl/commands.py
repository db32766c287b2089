"""The root of the CRCL commands and the commands about the session itself.

Every command is a frozen dataclass built with keywords, e.g.
``Dwell(command_id=5, seconds=2.5)``; ``command_id`` is the ``CommandID`` its
statuses echo (an integer >= 0), ``name`` the optional ``Name`` and ``guards`` the
sensor ``Guard`` elements any command may carry. The motion, setting and device
commands live in the modules named so; ``documents`` lists them all.
"""

from __future__ import annotations

from dataclasses import dataclass

from .binding import Nested, Record, many, one, opt
from .errors import CrclValueError
from .primitives import Guard
from .scalars import BOOLEAN, COMMAND_ID, COUNT, JOINT_NUMBER, STRING

__all__ = [
    "Command",
    "ConfigureJointReport",
    "ConfigureJointReports",
    "ConfigureStatusReport",
    "EndCanon",
    "GetStatus",
    "InitCanon",
    "LoopBlockEnd",
    "LoopBlockStart",
    "Message",
    "MiddleCommand",
    "RunProgram",
]


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
