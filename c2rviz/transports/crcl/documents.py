"""Command documents: ``<CRCLCommandInstance>`` bytes <-> typed commands.

``parse_command`` reads one document (as the splitter cuts them) into one of the
``COMMAND_TYPES``, refusing anything unsafe (see ``hardened``) or invalid (see
``binding`` and the command classes) with a ``CrclError`` whose ``command_id`` is set
whenever the document's CommandID could be read. ``write_command`` is its inverse.

The command element's ``xsi:type`` is found by its namespace URI, whatever prefix the
document binds to it; its value may carry a prefix, which is ignored (CRCL types have
no namespace). Elements are unqualified; a namespace on them is ignored too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, cast

from .binding import XSI_NAMESPACE, Nested, Record, one, opt, read_record, write_record
from .commands import (
    Command,
    ConfigureJointReports,
    ConfigureStatusReport,
    EndCanon,
    GetStatus,
    InitCanon,
    LoopBlockEnd,
    LoopBlockStart,
    Message,
    MiddleCommand,
    RunProgram,
)
from .device_commands import (
    CloseToolChanger,
    DisableGripper,
    DisableRobotParameterStatus,
    DisableSensor,
    EnableGripper,
    EnableRobotParameterStatus,
    EnableSensor,
    OpenToolChanger,
    SetEndEffector,
)
from .hardened import parse_xml
from .motion_commands import ActuateJoints, Dwell, MoveScrew, MoveThroughTo, MoveTo, StopMotion
from .scalars import COUNT, STRING
from .setting_commands import (
    SetAngleUnits,
    SetDefaultJointPositionsTolerances,
    SetEndEffectorParameters,
    SetEndPoseTolerance,
    SetForceUnits,
    SetIntermediatePoseTolerance,
    SetLengthUnits,
    SetMotionCoordination,
    SetRobotParameters,
    SetRotAccel,
    SetRotSpeed,
    SetTorqueUnits,
    SetTransAccel,
    SetTransSpeed,
)

__all__ = [
    "COMMAND_TYPES",
    "MIDDLE_COMMAND_TYPES",
    "XML_DECLARATION",
    "CommandInstance",
    "parse_command",
    "parse_instance",
    "write_command",
    "write_instance",
]

MIDDLE_COMMAND_TYPES: Final[tuple[type[MiddleCommand], ...]] = (
    GetStatus,
    MoveTo,
    MoveThroughTo,
    MoveScrew,
    ActuateJoints,
    StopMotion,
    Dwell,
    Message,
    SetLengthUnits,
    SetAngleUnits,
    SetForceUnits,
    SetTorqueUnits,
    SetTransSpeed,
    SetTransAccel,
    SetRotSpeed,
    SetRotAccel,
    SetEndPoseTolerance,
    SetIntermediatePoseTolerance,
    SetDefaultJointPositionsTolerances,
    ConfigureJointReports,
    ConfigureStatusReport,
    SetEndEffector,
    SetEndEffectorParameters,
    OpenToolChanger,
    CloseToolChanger,
    SetMotionCoordination,
    EnableGripper,
    DisableGripper,
    EnableSensor,
    DisableSensor,
    SetRobotParameters,
    EnableRobotParameterStatus,
    DisableRobotParameterStatus,
    RunProgram,
    LoopBlockStart,
    LoopBlockEnd,
)
"""Every concrete type derived from ``MiddleCommandType`` in CRCLCommands.xsd."""

COMMAND_TYPES: Final[tuple[type[Command], ...]] = (InitCanon, EndCanon, *MIDDLE_COMMAND_TYPES)
"""Every concrete CRCL command type (38), InitCanon and EndCanon first."""

COMMAND: Final = Nested(*COMMAND_TYPES, abstract=True)
MIDDLE_COMMAND: Final = Nested(*MIDDLE_COMMAND_TYPES, abstract=True)
XML_DECLARATION: Final = '<?xml version="1.0" encoding="UTF-8"?>'
ROOT_ATTRIBUTES: Final = f' xmlns:xsi="{XSI_NAMESPACE}"'


@dataclass(frozen=True, kw_only=True)
class CommandInstance(Record):
    """A whole command document: the command, and where it came from if it is part of
    a program (``program_index``: InitCanon is 0, the first middle command 1)."""

    XSI_TYPE = "CRCLCommandInstanceType"
    name: str | None = opt("Name", STRING)
    command: Command = one("CRCLCommand", COMMAND)
    program_file: str | None = opt("ProgramFile", STRING)
    program_index: int | None = opt("ProgramIndex", COUNT)
    program_length: int | None = opt("ProgramLength", COUNT)


_INSTANCE: Final = Nested(CommandInstance)


def parse_instance(doc: bytes) -> CommandInstance:
    """The ``CRCLCommandInstance`` of one document.

    Args:
        doc: One UTF-8 document, as ``DocumentSplitter`` cuts them.

    Raises:
        CrclError: ``CrclSyntaxError`` (unsafe, malformed, other root),
            ``UnknownCrclType`` or ``CrclValueError``; ``command_id`` set when known.
    """
    root = parse_xml(doc, ("CRCLCommandInstance",))
    return cast(CommandInstance, read_record(_INSTANCE, root))


def parse_command(doc: bytes) -> Command:
    """The command of one ``CRCLCommandInstance`` document (see ``parse_instance``)."""
    return parse_instance(doc).command


def write_instance(instance: CommandInstance) -> bytes:
    """The document for ``instance``: declaration and compact XML, no trailing newline."""
    out = [XML_DECLARATION]
    write_record(instance, "CRCLCommandInstance", out, None, ROOT_ATTRIBUTES)
    return "".join(out).encode()


def write_command(command: Command) -> bytes:
    """The ``CRCLCommandInstance`` document for ``command`` (inverse of ``parse_command``)."""
    if not isinstance(command, COMMAND_TYPES):
        raise TypeError(f"not a CRCL command: {command!r}")
    return write_instance(CommandInstance(command=command))
