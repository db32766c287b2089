"""Program files: a ``<CRCLProgram>`` of InitCanon, middle commands and EndCanon."""

from __future__ import annotations

import pytest

from c2rviz.transports.crcl import (
    CrclSyntaxError,
    CrclValueError,
    Dwell,
    EndCanon,
    GetStatus,
    InitCanon,
    MoveTo,
    SetEndEffector,
    UnknownCrclType,
    parse_program,
    write_program,
)

PROGRAM = b"""<?xml version="1.0" encoding="UTF-8"?>
<!-- A pick: open, move down, close, move up. -->
<CRCLProgram
  xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
  xsi:noNamespaceSchemaLocation="../xmlSchemas/CRCLProgramInstance.xsd">
  <Name>pick</Name>
  <InitCanon>
    <Name>start</Name>
    <CommandID>1</CommandID>
  </InitCanon>
  <MiddleCommand xsi:type="SetEndEffectorType">
    <CommandID>2</CommandID>
    <Setting>1.0</Setting>
  </MiddleCommand>
  <MiddleCommand xsi:type="MoveToType">
    <CommandID>3</CommandID>
    <MoveStraight>true</MoveStraight>
    <EndPosition>
      <Point><X>0.5</X> <Y>0</Y> <Z>0.1</Z></Point>
      <XAxis><I>1</I> <J>0</J> <K>0</K></XAxis>
      <ZAxis><I>0</I> <J>0</J> <K>-1</K></ZAxis>
    </EndPosition>
  </MiddleCommand>
  <MiddleCommand xsi:type="DwellType">
    <CommandID>4</CommandID>
    <DwellTime>0.5</DwellTime>
  </MiddleCommand>
  <EndCanon>
    <CommandID>5</CommandID>
  </EndCanon>
</CRCLProgram>
"""


def test_program_parses_in_order() -> None:
    commands = parse_program(PROGRAM)
    assert [type(command) for command in commands] == [
        InitCanon, SetEndEffector, MoveTo, Dwell, EndCanon,
    ]  # fmt: skip
    assert [command.command_id for command in commands] == [1, 2, 3, 4, 5]
    assert commands[0].name == "start"
    assert parse_program(write_program(commands)) == commands


BAD = [
    ("no-init", PROGRAM.replace(b"<InitCanon>", b"<Foo>").replace(b"</InitCanon>", b"</Foo>"),
     CrclSyntaxError, "starts with <Foo>"),
    ("end-first", PROGRAM.replace(b"<Name>pick</Name>", b"<EndCanon><CommandID>0</CommandID>"
                                  b"</EndCanon>"), CrclSyntaxError, "starts with <EndCanon>"),
    ("init-as-middle", PROGRAM.replace(b"SetEndEffectorType", b"InitCanonType"),
     UnknownCrclType, "unknown xsi:type 'InitCanonType'"),
    ("bad-middle-value", PROGRAM.replace(b"<DwellTime>0.5", b"<DwellTime>-2"),
     CrclValueError, "MiddleCommand[3]/DwellTime: -2.0 is out of range"),
    ("command-root", b"<CRCLCommandInstance/>", CrclSyntaxError, "is not <CRCLProgram>"),
]  # fmt: skip


@pytest.mark.parametrize(("doc", "error", "words"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_programs(doc: bytes, error: type[Exception], words: str) -> None:
    with pytest.raises(error) as caught:
        parse_program(doc)
    assert words in str(caught.value)


def test_bad_middle_value_names_its_command() -> None:
    with pytest.raises(CrclValueError) as caught:
        parse_program(PROGRAM.replace(b"<DwellTime>0.5", b"<DwellTime>-2"))
    assert (caught.value.command_id, caught.value.command_type) == (4, "DwellType")


def test_program_size_limit_is_larger_than_a_command() -> None:
    move = PROGRAM[PROGRAM.index(b'  <MiddleCommand xsi:type="MoveToType">') :]
    move = move[: move.index(b"</MiddleCommand>") + len(b"</MiddleCommand>\n")]
    big = PROGRAM.replace(b"  <EndCanon>", move * 6000 + b"  <EndCanon>")
    assert len(big) > 1 << 20
    assert len(parse_program(big)) == 5 + 6000
    with pytest.raises(CrclSyntaxError, match="over the limit"):
        parse_program(big, max_bytes=1 << 20)


def test_write_program_checks_its_ends() -> None:
    with pytest.raises(CrclValueError, match="starts with InitCanon and ends with EndCanon"):
        write_program([GetStatus(command_id=1), EndCanon(command_id=2)])
    with pytest.raises(CrclValueError, match="command 1 of the program is not a middle command"):
        write_program([InitCanon(command_id=1), InitCanon(command_id=2), EndCanon(command_id=3)])
