"""Program documents: a ``<CRCLProgram>`` (InitCanon, MiddleCommand..., EndCanon).

Parsed with the same hardening and checks as single commands (see ``documents``),
with a larger size limit since a program file holds many commands. Unlike other
elements, a program's children must come in order: InitCanon first, EndCanon last.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final, cast

from .binding import Nested, Record, many, one, opt, read_record, write_record
from .commands import Command, EndCanon, InitCanon, MiddleCommand
from .documents import MIDDLE_COMMAND, ROOT_ATTRIBUTES, XML_DECLARATION
from .errors import CrclSyntaxError, CrclValueError
from .hardened import parse_xml
from .scalars import STRING

__all__ = ["MAX_PROGRAM_BYTES", "Program", "parse_program", "write_program"]

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
