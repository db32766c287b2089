"""CRCL documents: ``<CRCLCommandInstance>`` and ``<CRCLProgram>`` bytes <-> typed commands.

``parse_xml`` parses one document with lxml, hardened against hostile XML. Refused
before the parser sees a byte: a document over ``MAX_DOCUMENT_BYTES``, one that is not
UTF-8 (a UTF-16 byte-order mark, NUL bytes, a declared encoding other than UTF-8 or
ASCII) and any ``<!DOCTYPE`` or ``<!ENTITY`` (upper or lower case, anywhere, even in a
comment): CRCL needs no DTD, and without one there is no entity to expand, so neither
XXE (an external entity reading a local file or a URL) nor "billion laughs" (nested
entity expansion) can start. The lxml parser itself is configured not to resolve
entities, load DTDs or touch the network, and to keep its size limits
(``huge_tree=False``); comments and processing instructions are dropped. A DOCTYPE that
slipped past the byte scan would still be refused after parsing.

``parse_command`` reads one command document (as the splitter cuts them) into one of
the ``COMMAND_TYPES``, refusing anything unsafe or invalid (see ``binding`` and the
command classes) with a ``CrclError`` whose ``command_id`` is set whenever the
document's CommandID could be read. ``write_command`` is its inverse.

The command element's ``xsi:type`` is found by its namespace URI, whatever prefix the
document binds to it; its value may carry a prefix, which is ignored (CRCL types have
no namespace). Elements are unqualified; a namespace on them is ignored too.

``parse_program`` reads a program (InitCanon, MiddleCommand..., EndCanon) with the same
hardening and checks as single commands, with a larger size limit since a program file
holds many commands. Unlike other elements, a program's children must come in order:
InitCanon first, EndCanon last.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, cast

from lxml import etree

from ...protocol.limits import default
from .binding import XSI_NAMESPACE, Nested, Record, many, one, opt, read_record, write_record
from .commands import (
    ActuateJoints,
    CloseToolChanger,
    Command,
    ConfigureJointReports,
    ConfigureStatusReport,
    DisableGripper,
    DisableRobotParameterStatus,
    DisableSensor,
    Dwell,
    EnableGripper,
    EnableRobotParameterStatus,
    EnableSensor,
    EndCanon,
    GetStatus,
    InitCanon,
    LoopBlockEnd,
    LoopBlockStart,
    Message,
    MiddleCommand,
    MoveScrew,
    MoveThroughTo,
    MoveTo,
    OpenToolChanger,
    RunProgram,
    SetEndEffector,
    StopMotion,
)
from .errors import CrclSyntaxError, CrclValueError
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

MAX_DOCUMENT_BYTES: Final = default("crcl", "max_document_bytes")
"""The largest document accepted [bytes] (1 MiB), the splitter's default limit too."""

_FORBIDDEN = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)
_DECLARED = re.compile(rb"\A(?:\xef\xbb\xbf)?\s*<\?xml\b[^>]*?\bencoding\s*=\s*([\"'])(.*?)\1")
_UTF8_NAMES = {b"utf-8", b"utf8", b"us-ascii", b"ascii"}
_local = threading.local()


def _parser() -> etree.XMLParser:
    parser: etree.XMLParser | None = getattr(_local, "parser", None)
    if parser is None:  # one per thread: an lxml parser must not be shared between threads
        parser = etree.XMLParser(
            resolve_entities=False,
            no_network=True,
            load_dtd=False,
            dtd_validation=False,
            huge_tree=False,
            remove_comments=True,
            remove_pis=True,
            collect_ids=False,
        )
        _local.parser = parser
    return parser


def parse_xml(
    doc: bytes, roots: tuple[str, ...], max_bytes: int = MAX_DOCUMENT_BYTES
) -> etree._Element:
    """The root element of ``doc``, refused unless safe, well-formed and one of ``roots``.

    Args:
        doc: One whole document, UTF-8, with or without an ``<?xml?>`` declaration.
        roots: The root element names accepted (local names; a prefix is ignored).
        max_bytes: The largest document accepted [bytes].

    Raises:
        CrclSyntaxError: Too large, not UTF-8, a DOCTYPE or entity declaration,
            malformed XML, or another root element.
    """
    if not isinstance(doc, (bytes, bytearray, memoryview)):
        raise TypeError(f"a CRCL document is bytes, not {type(doc).__name__}")
    doc = bytes(doc)
    if len(doc) > max_bytes:
        raise CrclSyntaxError(f"document of {len(doc)} bytes is over the limit of {max_bytes}")
    if doc[:2] in (b"\xff\xfe", b"\xfe\xff") or b"\x00" in doc:
        raise CrclSyntaxError("document is not UTF-8 (UTF-16 or NUL bytes); CRCL here is UTF-8")
    declared = _DECLARED.match(doc)
    if declared and declared.group(2).lower() not in _UTF8_NAMES:
        name = declared.group(2).decode("ascii", "replace")
        raise CrclSyntaxError(f"encoding {name!r} is not accepted: documents must be UTF-8")
    forbidden = _FORBIDDEN.search(doc)
    if forbidden:
        what = forbidden.group(1).decode().upper()
        raise CrclSyntaxError(
            f"<!{what}> refused: CRCL documents may not have a DOCTYPE or declare entities"
        )
    try:
        root = etree.fromstring(doc, _parser())
    except etree.XMLSyntaxError as error:
        raise CrclSyntaxError(f"malformed XML: {error.msg[:160]}") from None
    if root.getroottree().docinfo.doctype:
        raise CrclSyntaxError("DOCTYPE refused: CRCL documents may not have a DOCTYPE")
    tag = root.tag
    local = tag.rpartition("}")[2] if isinstance(tag, str) else ""
    if local not in roots:
        expected = " or ".join(f"<{name}>" for name in roots)
        raise CrclSyntaxError(f"root element <{local[:40]}> is not {expected}")
    return root


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


# Program documents: a ``<CRCLProgram>``.

MAX_PROGRAM_BYTES: Final = 16 << 20
"""The largest program document accepted [bytes] (16 MiB: tens of thousands of moves)."""


@dataclass(frozen=True, kw_only=True)
class Program(Record):
    """A CRCL program (``CRCLProgramType``): run in order, InitCanon to EndCanon."""

    XSI_TYPE = "CRCLProgramType"
    name: str | None = opt("Name", STRING)
    init_canon: InitCanon = one("InitCanon", Nested(InitCanon))
    middle_commands: tuple[MiddleCommand, ...] = many("MiddleCommand", MIDDLE_COMMAND)
    end_canon: EndCanon = one("EndCanon", Nested(EndCanon))

    @property
    def commands(self) -> list[Command]:
        """Every command in order: InitCanon (index 0), the middle ones, EndCanon."""
        return [self.init_canon, *self.middle_commands, self.end_canon]


_PROGRAM: Final = Nested(Program)


def read_program(doc: bytes, *, max_bytes: int = MAX_PROGRAM_BYTES) -> Program:
    """The ``Program`` of one ``<CRCLProgram>`` document.

    Raises:
        CrclError: As ``documents.parse_instance``, or children out of order.
    """
    root = parse_xml(doc, ("CRCLProgram",), max_bytes)
    tags = [child.tag.rpartition("}")[2] for child in root if isinstance(child.tag, str)]
    tags = [tag for tag in tags if tag != "Name"]
    if tags and (tags[0] != "InitCanon" or tags[-1] != "EndCanon"):
        raise CrclSyntaxError(
            f"a CRCLProgram runs from <InitCanon> to <EndCanon>: it starts with "
            f"<{tags[0][:40]}> and ends with <{tags[-1][:40]}>"
        )
    return cast(Program, read_record(_PROGRAM, root))


def parse_program(doc: bytes, *, max_bytes: int = MAX_PROGRAM_BYTES) -> list[Command]:
    """Every command of a ``<CRCLProgram>`` document, in order (InitCanon first).

    Args:
        doc: The program file's bytes (UTF-8).
        max_bytes: The largest document accepted [bytes].
    """
    return read_program(doc, max_bytes=max_bytes).commands


def write_program(commands: Sequence[Command], name: str | None = None) -> bytes:
    """The ``<CRCLProgram>`` document of ``commands`` (InitCanon, middle ones, EndCanon).

    Raises:
        CrclValueError: The first is not an InitCanon, the last not an EndCanon, or
            one between is not a middle command.
    """
    items = list(commands)
    first = items[0] if items else None
    last = items[-1] if len(items) >= 2 else None
    if not isinstance(first, InitCanon) or not isinstance(last, EndCanon):
        raise CrclValueError("a program starts with InitCanon and ends with EndCanon")
    middle: list[MiddleCommand] = []
    for index, command in enumerate(items[1:-1], start=1):
        if not isinstance(command, MiddleCommand):
            raise CrclValueError(f"command {index} of the program is not a middle command")
        middle.append(command)
    program = Program(name=name, init_canon=first, middle_commands=tuple(middle), end_canon=last)
    out = [XML_DECLARATION]
    write_record(program, "CRCLProgram", out, None, ROOT_ATTRIBUTES)
    return "".join(out).encode()
