"""Written statuses follow CRCLStatus.xsd's structure, checked by rules written here.

The tests cannot load the schema (the project carries no copy), so the element orders
below are transcribed from it; the writer was also checked against the schema itself
with ``xmlschema`` during development.
"""

from __future__ import annotations

import math
import re
import xml.dom.minidom

import pytest
from crcl_strategies import statuses
from hypothesis import given, settings
from lxml import etree
from support import examples

from c2rviz.transports.crcl import (
    CommandStatus,
    CrclStatus,
    CrclValueError,
    JointLimit,
    JointStatus,
    JointStatuses,
    ParallelGripperStatus,
    ParameterSetting,
    Point,
    Pose,
    PoseStatus,
    PoseTolerance,
    RotSpeedAbsolute,
    SettingsStatus,
    TransSpeedRelative,
    Vector,
    parse_status,
    write_status,
    xml_safe_text,
)

XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"
ORDER = {
    "CRCLStatus": ["Name", "CommandStatus", "JointStatuses", "PoseStatus", "GripperStatus",
                   "SettingsStatus", "SensorStatuses", "GuardsStatuses"],
    "CommandStatus": ["Name", "CommandID", "StatusID", "CommandState", "StateDescription",
                      "ProgramFile", "ProgramIndex", "ProgramLength", "OverridePercent"],
    "JointStatus": ["Name", "JointNumber", "JointPosition", "JointTorqueOrForce", "JointVelocity"],
    "PoseStatus": ["Name", "Pose", "Twist", "Wrench", "Configuration"],
    "Pose": ["Name", "Point", "XAxis", "ZAxis"],
    "Point": ["Name", "X", "Y", "Z"],
    "GripperStatus": ["Name", "GripperName", "GripperOption", "HoldingObject", "Separation",
                      "IsPowered", "Finger1Position", "Finger2Position", "Finger3Position",
                      "Finger1Force", "Finger2Force", "Finger3Force"],
    "SettingsStatus": ["Name", "AngleUnitName", "EndEffectorParameterSetting",
                       "EndEffectorSetting", "ForceUnitName", "JointLimits",
                       "IntermediatePoseTolerance", "LengthUnitName", "MaxCartesianLimit",
                       "MinCartesianLimit", "MotionCoordinated", "EndPoseTolerance",
                       "RobotParameterSetting", "RotAccelAbsolute", "RotAccelRelative",
                       "RotSpeedAbsolute", "RotSpeedRelative", "TorqueUnitName",
                       "TransAccelAbsolute", "TransAccelRelative", "TransSpeedAbsolute",
                       "TransSpeedRelative", "JointTolerances"],
    "JointLimits": ["Name", "JointNumber", "JointMinPosition", "JointMaxPosition",
                    "JointMaxTorqueOrForce", "JointMaxVelocity"],
    "EndPoseTolerance": ["Name", "XPointTolerance", "YPointTolerance", "ZPointTolerance",
                         "XAxisTolerance", "ZAxisTolerance"],
}  # fmt: skip
REQUIRED = {
    "CRCLStatus": ["CommandStatus"],
    "CommandStatus": ["CommandID", "StatusID", "CommandState"],
    "JointStatus": ["JointNumber"],
    "PoseStatus": ["Pose"],
    "Pose": ["Point", "XAxis", "ZAxis"],
}
NUMBERS = {"X", "Y", "Z", "I", "J", "K", "JointPosition", "JointVelocity", "JointTorqueOrForce",
           "Separation", "Setting", "Fraction", "EndEffectorSetting", "XPointTolerance",
           "JointMinPosition", "JointMaxPosition"}  # fmt: skip
DOUBLE = re.compile(r"-?[0-9]+(\.[0-9]+)?(e[+-]?[0-9]+)?")
STATES = {"CRCL_Done", "CRCL_Error", "CRCL_Working", "CRCL_Ready"}

POSE = Pose(Point(0.4123456789012345, -0.25, 0.6), Vector(1, 0, 0), Vector(0, 0, -1))
FULL = CrclStatus(
    command_status=CommandStatus(command_id=7, status_id=42, state="CRCL_Error",
                                 description="MoveToType: link_6 would hit table",
                                 program_file="demo.xml", program_index=3, program_length=9),
    joint_statuses=JointStatuses(tuple(JointStatus(joint_number=n, position=n / 7, velocity=0.0)
                                       for n in range(1, 8))),
    pose_status=PoseStatus(pose=POSE),
    gripper_status=ParallelGripperStatus(gripper_name="hand", separation=0.08),
    settings_status=SettingsStatus(
        angle_unit="radian", end_effector_setting=1.0,
        joint_limits=(JointLimit(joint_number=1, min_position=-3.0, max_position=3.0),),
        length_unit="meter", motion_coordinated=False,
        end_pose_tolerance=PoseTolerance(x_point=1e-3),
        robot_parameters=(ParameterSetting("mode", "sim"),),
        rot_speed_absolute=RotSpeedAbsolute(1.0), trans_speed_relative=TransSpeedRelative(0.5),
    ),
)  # fmt: skip


def check_structure(doc: bytes) -> None:
    """The rules a CRCLStatus document must meet, from CRCLStatus.xsd."""
    head = b'<?xml version="1.0" encoding="UTF-8"?><CRCLStatus '
    assert doc.startswith(head), doc[:80]
    assert not doc.endswith(b"\n") and doc.endswith(b"</CRCLStatus>")
    root = etree.fromstring(doc)
    for element in root.iter():
        tag = element.tag
        children = [child.tag for child in element]
        order = ORDER.get(tag)
        if order is not None:
            positions = [order.index(child) for child in children]  # unknown -> ValueError
            assert positions == sorted(positions), (tag, children)
        for needed in REQUIRED.get(tag, []):
            assert needed in children, (tag, needed)
        if tag in NUMBERS and len(element) == 0:  # (a JointTolerances Setting has children)
            assert DOUBLE.fullmatch(element.text or ""), (tag, element.text)
            assert math.isfinite(float(element.text or ""))
        if tag == "CommandState":
            assert element.text in STATES
        if tag == "GripperStatus":
            assert element.get(XSI_TYPE) in {
                "ParallelGripperStatusType", "VacuumGripperStatusType",
                "ThreeFingerGripperStatusType",
            }  # fmt: skip
        if tag == "JointStatuses":
            numbers = [int(child.findtext("JointNumber") or "0") for child in element]
            assert numbers and len(set(numbers)) == len(numbers) and min(numbers) >= 1


def test_full_status_follows_the_schema_rules() -> None:
    doc = write_status(FULL)
    check_structure(doc)
    assert b"<JointPosition>0.14285714285714285</JointPosition>" in doc  # repr: exact
    assert b'<GripperStatus xsi:type="ParallelGripperStatusType">' in doc
    assert parse_status(doc) == FULL


@settings(max_examples=examples(150), deadline=None)
@given(statuses)
def test_any_status_follows_the_schema_rules(status: CrclStatus) -> None:
    check_structure(write_status(status))


def test_python_minidom_reads_one_status() -> None:
    """NIST's 2015 Python shell parses each status read with xml.dom.minidom."""
    dom = xml.dom.minidom.parseString(write_status(FULL))
    assert dom.getElementsByTagName("CommandID")[0].firstChild.data == "7"  # type: ignore[union-attr]


def test_a_pushed_status_fits_one_1k_read() -> None:
    compact = CrclStatus(
        command_status=CommandStatus(command_id=2**40, status_id=2**40, state="CRCL_Working"),
        pose_status=PoseStatus(
            pose=Pose(Point(-0.1234567890123456, 0.9876543210987654, -0.5555555555555556),
                      Vector(0.7071067811865476, -0.7071067811865475, 1.2e-17),
                      Vector(-0.7071067811865475, -0.7071067811865476, -2.2e-16)),
        ),
    )  # fmt: skip
    assert len(write_status(compact)) < 1024


def test_status_values_are_checked() -> None:
    with pytest.raises(CrclValueError, match="'CRCL_Bored' is not one of: CRCL_Done"):
        CommandStatus(command_id=1, status_id=1, state="CRCL_Bored")
    with pytest.raises(CrclValueError, match="JointStatus: needs at least 1 JointStatus, got 0"):
        JointStatuses(())
    with pytest.raises(
        CrclValueError, match="joint 2 appears twice: each joint is reported at most once"
    ):
        JointStatuses((JointStatus(joint_number=2), JointStatus(joint_number=2)))
    with pytest.raises(CrclValueError, match="cannot be written in XML"):
        CommandStatus(command_id=1, status_id=1, state="CRCL_Error", description="bad \x07 byte")
    safe = xml_safe_text("bad \x07 byte \ud800")
    assert safe == "bad \ufffd byte \ufffd"
    status = CommandStatus(command_id=1, status_id=1, state="CRCL_Error", description=safe)
    doc = write_status(CrclStatus(command_status=status))
    assert parse_status(doc).command_status.description == safe
    with pytest.raises(TypeError):
        write_status(status)  # type: ignore[arg-type]
