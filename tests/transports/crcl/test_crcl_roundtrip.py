"""Write-then-parse gives back the same record, for every CRCL type (hypothesis)."""

from __future__ import annotations

import math

import pytest
from crcl_strategies import commands, record_of, statuses, xml_text
from hypothesis import given, settings
from hypothesis import strategies as st
from support import examples

from c2rviz.transports.crcl import (
    COMMAND_TYPES,
    MIDDLE_COMMAND_TYPES,
    Command,
    CommandInstance,
    CrclStatus,
    DocumentSplitter,
    EndCanon,
    InitCanon,
    parse_command,
    parse_instance,
    parse_program,
    parse_status,
    write_command,
    write_instance,
    write_program,
    write_status,
)


def test_every_schema_command_type_has_a_class() -> None:
    names = {cls.XSI_TYPE for cls in COMMAND_TYPES}
    assert len(names) == len(COMMAND_TYPES) == 38
    for expected in (
        "InitCanonType", "EndCanonType", "GetStatusType", "MoveToType", "MoveThroughToType",
        "MoveScrewType", "ActuateJointsType", "StopMotionType", "DwellType", "MessageType",
        "SetLengthUnitsType", "SetAngleUnitsType", "SetForceUnitsType", "SetTorqueUnitsType",
        "SetTransSpeedType", "SetTransAccelType", "SetRotSpeedType", "SetRotAccelType",
        "SetEndPoseToleranceType", "SetIntermediatePoseToleranceType",
        "SetDefaultJointPositonsTolerancesType", "ConfigureJointReportsType",
        "ConfigureStatusReportType", "SetEndEffectorType", "SetEndEffectorParametersType",
        "OpenToolChangerType", "CloseToolChangerType", "SetMotionCoordinationType",
        "EnableGripperType", "DisableGripperType", "EnableSensorType", "DisableSensorType",
        "SetRobotParametersType", "EnableRobotParameterStatusType",
        "DisableRobotParameterStatusType", "RunProgramType", "LoopBlockStartType",
        "LoopBlockEndType",
    ):  # fmt: skip
        assert expected in names
    assert all(issubclass(cls, Command) for cls in COMMAND_TYPES)
    assert set(MIDDLE_COMMAND_TYPES) == set(COMMAND_TYPES) - {InitCanon, EndCanon}


@pytest.mark.parametrize("cls", COMMAND_TYPES, ids=[cls.__name__ for cls in COMMAND_TYPES])
@settings(max_examples=examples(15), deadline=None)
@given(data=st.data())
def test_each_command_type_round_trips(cls: type[Command], data: st.DataObject) -> None:
    command = data.draw(record_of(cls))
    doc = write_command(command)
    assert parse_command(doc) == command
    assert write_command(parse_command(doc)) == doc


@settings(max_examples=examples(200), deadline=None)
@given(commands)
def test_commands_round_trip_exactly(command: Command) -> None:
    doc = write_command(command)
    assert doc.startswith(b'<?xml version="1.0" encoding="UTF-8"?><CRCLCommandInstance ')
    again = parse_command(doc)
    assert again == command
    assert _signs(again) == _signs(command)  # -0.0 stays -0.0: floats are written exactly


def _signs(record: object) -> list[float]:
    found: list[float] = []
    for value in getattr(record, "__dict__", {}).values():
        for item in value if isinstance(value, tuple) else (value,):
            if isinstance(item, float):
                found.append(math.copysign(1.0, item))
            elif hasattr(item, "__dict__"):
                found += _signs(item)
    return found


@settings(max_examples=examples(50), deadline=None)
@given(commands, st.none() | xml_text, st.none() | st.integers(0, 99))
def test_instances_round_trip(
    command: Command, program_file: str | None, index: int | None
) -> None:
    instance = CommandInstance(command=command, program_file=program_file, program_index=index)
    assert parse_instance(write_instance(instance)) == instance


@settings(max_examples=examples(100), deadline=None)
@given(statuses)
def test_statuses_round_trip(status: CrclStatus) -> None:
    assert parse_status(write_status(status)) == status


@settings(max_examples=examples(40), deadline=None)
@given(
    record_of(InitCanon),
    st.lists(st.one_of([record_of(cls) for cls in MIDDLE_COMMAND_TYPES]), max_size=5),
    record_of(EndCanon),
)
def test_programs_round_trip(first: InitCanon, middle: list[Command], last: EndCanon) -> None:
    commands = [first, *middle, last]
    assert parse_program(write_program(commands)) == commands


@settings(max_examples=examples(50), deadline=None)
@given(st.lists(commands, min_size=1, max_size=5), st.integers(1, 97))
def test_written_commands_split_back(batch: list[Command], chunk: int) -> None:
    stream = b"".join(write_command(command) for command in batch)
    splitter = DocumentSplitter()
    docs = [
        item for i in range(0, len(stream), chunk) for item in splitter.feed(stream[i : i + chunk])
    ]
    assert [parse_command(doc) for doc in docs if isinstance(doc, bytes)] == batch
