"""Command documents as NIST's tools write them, and every way one can be wrong.

Good documents: namespaced ``xsi:type`` under varied prefixes, indentation, the
``<?xml?>`` declaration, comments, ``Name`` elements. Bad ones: each refusal of
issue 24, with the ``command_id`` the error must carry and words its message must say.
"""

from __future__ import annotations

import pytest

from c2rviz.errors import C2rvizError
from c2rviz.transports.crcl import (
    ActuateJoint,
    ActuateJoints,
    CrclError,
    CrclSyntaxError,
    CrclValueError,
    Dwell,
    EndCanon,
    GetStatus,
    InitCanon,
    JointForceTorque,
    JointSpeedAccel,
    Message,
    MoveThroughTo,
    MoveTo,
    Point,
    Pose,
    PoseAndSet,
    RotSpeedRelative,
    SetAngleUnits,
    SetEndEffector,
    SetLengthUnits,
    SetRotSpeed,
    SetTransSpeed,
    StopMotion,
    TransSpeedAbsolute,
    TransSpeedRelative,
    UnknownCrclType,
    Vector,
    parse_command,
    parse_instance,
)

XSI = "http://www.w3.org/2001/XMLSchema-instance"
DOWN = Pose(Point(0.5, 0.0, 0.3), Vector(1.0, 0.0, 0.0), Vector(0.0, 0.0, -1.0))


def instance(body: str, kind: str, prefix: str = "xsi", declaration: bool = True) -> bytes:
    """A command document as NIST writes them: declaration, indentation, xsi:type."""
    head = '<?xml version="1.0" encoding="UTF-8"?>\n' if declaration else ""
    return (
        f'{head}<CRCLCommandInstance\n  xmlns:{prefix}="{XSI}">\n'
        f'  <CRCLCommand {prefix}:type="{kind}">\n{body}\n  </CRCLCommand>\n'
        f"</CRCLCommandInstance>\n"
    ).encode()


POSE_XML = """    <EndPosition>
      <Point>
        <X>0.5</X> <Y>0</Y> <Z>0.3</Z>
      </Point>
      <XAxis>
        <I>1</I> <J>0</J> <K>0</K>
      </XAxis>
      <ZAxis>
        <I>0</I> <J>0</J> <K>-1</K>
      </ZAxis>
    </EndPosition>"""

THROUGH = instance(
    "<CommandID>5</CommandID><MoveStraight>false</MoveStraight>"
    + POSE_XML.replace("EndPosition", "Waypoint") * 2
    + "<NumPositions>2</NumPositions>",
    "MoveThroughToType",
)
ACTUATE = instance(
    """    <CommandID>6</CommandID>
<ActuateJoint>
  <JointNumber>1</JointNumber>
  <JointPosition>0.25</JointPosition>
  <JointDetails xsi:type="JointSpeedAccelType">
    <JointSpeed>1.5</JointSpeed>
    <JointAccel>3</JointAccel>
  </JointDetails>
</ActuateJoint>
<ActuateJoint>
  <JointNumber>3</JointNumber>
  <JointPosition>-1E-1</JointPosition>
  <JointDetails xsi:type="JointForceTorqueType"/>
</ActuateJoint>""",
    "ActuateJointsType",
)

GOOD = [
    ("init", instance("    <CommandID>1</CommandID>", "InitCanonType"), InitCanon(command_id=1)),
    (
        "init-named-no-declaration",
        instance(
            "    <Name>start</Name>\n    <CommandID>1</CommandID>",
            "InitCanonType",
            declaration=False,
        ),  # fmt: skip
        InitCanon(command_id=1, name="start"),
    ),
    ("end", instance("<CommandID>99</CommandID>", "EndCanonType", "x"), EndCanon(command_id=99)),
    ("get-status", instance("<CommandID>0</CommandID>", "GetStatusType"), GetStatus(command_id=0)),
    (
        "move-to-prefix-q",
        instance(
            f"    <CommandID>2</CommandID>\n    <MoveStraight>false</MoveStraight>\n{POSE_XML}",
            "MoveToType",
            "q",
        ),  # fmt: skip
        MoveTo(command_id=2, move_straight=False, end_position=DOWN),
    ),
    (
        "move-to-straight-1-and-comment",
        instance(
            f"<CommandID>3</CommandID><!-- straight -->\n<MoveStraight> 1 </MoveStraight>"
            f"{POSE_XML}",
            "MoveToType",
            "schema",
        ),  # fmt: skip
        MoveTo(command_id=3, move_straight=True, end_position=DOWN),
    ),
    (
        "move-to-pose-and-set",
        instance(
            "<CommandID>4</CommandID><MoveStraight>true</MoveStraight>"
            + POSE_XML.replace("<EndPosition>", '<EndPosition xsi:type="PoseAndSetType">').replace(
                "</ZAxis>",
                "</ZAxis><Coordinated>true</Coordinated>"
                '<TransSpeed xsi:type="TransSpeedRelativeType"><Fraction>0.9</Fraction>'
                "</TransSpeed>",
            ),  # fmt: skip
            "MoveToType",
        ),
        MoveTo(
            command_id=4,
            move_straight=True,
            end_position=PoseAndSet(
                DOWN.point,
                DOWN.x_axis,
                DOWN.z_axis,
                coordinated=True,
                trans_speed=TransSpeedRelative(0.9),
            ),  # fmt: skip
        ),
    ),
    (
        "move-through-to",
        THROUGH,
        MoveThroughTo(command_id=5, move_straight=False, waypoints=(DOWN, DOWN), num_positions=2),
    ),
    (
        "actuate-joints",
        ACTUATE,
        ActuateJoints(
            command_id=6,
            joints=(
                ActuateJoint(
                    joint_number=1, position=0.25, details=JointSpeedAccel(speed=1.5, accel=3.0)
                ),  # fmt: skip
                ActuateJoint(joint_number=3, position=-0.1, details=JointForceTorque()),
            ),
        ),
    ),
    (
        "stop",
        instance(
            "<CommandID>7</CommandID><StopCondition>Immediate</StopCondition>", "StopMotionType"
        ),  # fmt: skip
        StopMotion(command_id=7, condition="Immediate"),
    ),
    (
        "dwell",
        instance("<CommandID>8</CommandID><DwellTime>.5</DwellTime>", "DwellType"),
        Dwell(command_id=8, seconds=0.5),
    ),  # fmt: skip
    (
        "message-keeps-spaces-and-escapes",
        instance(
            "<CommandID>9</CommandID><Message>  a &lt;b&gt; &amp; &#233;  </Message>", "MessageType"
        ),  # fmt: skip
        Message(command_id=9, message="  a <b> & \u00e9  "),
    ),
    (
        "message-cdata",
        instance("<CommandID>9</CommandID><Message><![CDATA[x < y]]></Message>", "MessageType"),
        Message(command_id=9, message="x < y"),
    ),
    (
        "length-units",
        instance("<CommandID>10</CommandID><UnitName>millimeter</UnitName>", "SetLengthUnitsType"),
        SetLengthUnits(command_id=10, unit="millimeter"),
    ),
    (
        "angle-units",
        instance("<CommandID>11</CommandID><UnitName> degree </UnitName>", "SetAngleUnitsType"),
        SetAngleUnits(command_id=11, unit="degree"),
    ),
    (
        "trans-speed-absolute",
        instance(
            '<CommandID>12</CommandID><TransSpeed xsi:type="TransSpeedAbsoluteType">'
            "<Setting>250</Setting></TransSpeed>",
            "SetTransSpeedType",
        ),  # fmt: skip
        SetTransSpeed(command_id=12, speed=TransSpeedAbsolute(250.0)),
    ),
    (
        "rot-speed-relative-prefixed-value",
        instance(
            '<CommandID>13</CommandID><RotSpeed xsi:type="xsi:RotSpeedRelativeType">'
            "<Fraction>1</Fraction></RotSpeed>",
            "SetRotSpeedType",
        ),  # fmt: skip
        SetRotSpeed(command_id=13, speed=RotSpeedRelative(1.0)),
    ),
    (
        "end-effector",
        instance("<CommandID>14</CommandID><Setting>0</Setting>", "SetEndEffectorType"),
        SetEndEffector(command_id=14, setting=0.0),
    ),
    (
        "namespaced-elements-and-big-id",
        b'<c:CRCLCommandInstance xmlns:c="urn:crcl" xmlns:i="' + XSI.encode() + b'">'
        b'<c:CRCLCommand i:type="GetStatusType"><c:CommandID>9223372036854775807</c:CommandID>'
        b"</c:CRCLCommand></c:CRCLCommandInstance>",
        GetStatus(command_id=2**63 - 1),
    ),
]


@pytest.mark.parametrize(("doc", "expected"), [g[1:] for g in GOOD], ids=[g[0] for g in GOOD])
def test_good_documents_parse(doc: bytes, expected: object) -> None:
    assert parse_command(doc) == expected


def test_instance_keeps_program_fields() -> None:
    doc = instance("<CommandID>3</CommandID>", "GetStatusType").replace(
        b"</CRCLCommand>",
        b"</CRCLCommand><ProgramFile>p.xml</ProgramFile><ProgramIndex>2</ProgramIndex>"
        b"<ProgramLength>7</ProgramLength>",
    )
    got = parse_instance(doc)
    assert (got.program_file, got.program_index, got.program_length) == ("p.xml", 2, 7)


MOVE = f"<CommandID>5</CommandID><MoveStraight>false</MoveStraight>{POSE_XML}"
BAD = [
    # (id, document, error class, command_id, words in the message)
    ("malformed", b"<CRCLCommandInstance><CRCLCommand>", CrclSyntaxError, None, "malformed XML"),
    ("truncated", instance(MOVE, "MoveToType")[:-40], CrclSyntaxError, None, "malformed"),
    ("not-xml", b"joints 0 0 0\n", CrclSyntaxError, None, "malformed"),
    ("wrong-root", b"<CRCLStatus/>", CrclSyntaxError, None, "<CRCLCommandInstance>"),
    ("unknown-type", instance(MOVE, "MoveToTyp"), UnknownCrclType, 5, "did you mean MoveToType"),
    (
        "no-xsi-type",
        instance(MOVE, "MoveToType").replace(b' xsi:type="MoveToType"', b""),
        CrclValueError,
        5,
        "xsi:type is missing (it must name a CRCL type)",
    ),  # fmt: skip
    (
        "type-without-namespace",
        instance(MOVE, "MoveToType").replace(b"xsi:type", b"type"),
        CrclValueError,
        5,
        "xsi:type is missing (it must name a CRCL type)",
    ),  # fmt: skip
    (
        "no-command-id",
        instance("<MoveStraight>1</MoveStraight>" + POSE_XML, "MoveToType"),
        CrclValueError,
        None,
        "missing required element <CommandID>",
    ),  # fmt: skip
    (
        "command-id-text",
        instance("<CommandID>seven</CommandID>", "GetStatusType"),
        CrclValueError,
        None,
        "'seven' is not an integer",
    ),  # fmt: skip
    (
        "command-id-float",
        instance("<CommandID>1.5</CommandID>", "GetStatusType"),
        CrclValueError,
        None,
        "not an integer",
    ),  # fmt: skip
    (
        "command-id-negative",
        instance("<CommandID>-1</CommandID>", "GetStatusType"),
        CrclValueError,
        None,
        "non-negative",
    ),  # fmt: skip
    (
        "command-id-huge",
        instance("<CommandID>9223372036854775808</CommandID>", "GetStatusType"),
        CrclValueError,
        None,
        "out of range",
    ),  # fmt: skip
    (
        "nan",
        instance(MOVE.replace("<X>0.5</X>", "<X>NaN</X>"), "MoveToType"),
        CrclValueError,
        5,
        "EndPosition/Point/X: NaN is not allowed",
    ),  # fmt: skip
    (
        "inf",
        instance(MOVE.replace("<Z>0.3</Z>", "<Z>-INF</Z>"), "MoveToType"),
        CrclValueError,
        5,
        "finite",
    ),  # fmt: skip
    (
        "overflow",
        instance(MOVE.replace("<Z>0.3</Z>", "<Z>1e999</Z>"), "MoveToType"),
        CrclValueError,
        5,
        "too large",
    ),  # fmt: skip
    (
        "python-only-number",
        instance(MOVE.replace("<Z>0.3</Z>", "<Z>1_0</Z>"), "MoveToType"),
        CrclValueError,
        5,
        "'1_0' is not a number",
    ),  # fmt: skip
    (
        "empty-number",
        instance(MOVE.replace("<Z>0.3</Z>", "<Z/>"), "MoveToType"),
        CrclValueError,
        5,
        "Z: empty",
    ),  # fmt: skip
    (
        "elements-in-number",
        instance(MOVE.replace("<Z>0.3</Z>", "<Z><V>1</V></Z>"), "MoveToType"),
        CrclValueError,
        5,
        "not elements",
    ),  # fmt: skip
    (
        "missing-element",
        instance(MOVE.replace("<Y>0</Y>", ""), "MoveToType"),
        CrclValueError,
        5,
        "missing required element <Y>",
    ),  # fmt: skip
    (
        "missing-pose",
        instance("<CommandID>5</CommandID><MoveStraight>0</MoveStraight>", "MoveToType"),
        CrclValueError,
        5,
        "<EndPosition>",
    ),  # fmt: skip
    (
        "unknown-element",
        instance(MOVE.replace("<Y>0</Y>", "<Y>0</Y><W>1</W>"), "MoveToType"),
        CrclValueError,
        5,
        "unexpected element <W> (expected: X, Y, Z)",
    ),  # fmt: skip
    (
        "twice",
        instance(MOVE.replace("<Y>0</Y>", "<Y>0</Y><Y>1</Y>"), "MoveToType"),
        CrclValueError,
        5,
        "more than once",
    ),  # fmt: skip
    (
        "bad-boolean",
        instance(MOVE.replace(">false<", ">yes<"), "MoveToType"),
        CrclValueError,
        5,
        "'yes' is not a boolean",
    ),  # fmt: skip
    (
        "axes-not-orthogonal",
        instance(
            MOVE.replace("<I>1</I>", "<I>1</I>", 1).replace("<K>0</K>", "<K>0.1</K>", 1),
            "MoveToType",
        ),
        CrclValueError,
        5,
        "orthogonal",
    ),  # fmt: skip
    (
        "zero-axis",
        instance(MOVE.replace("<I>1</I>", "<I>0</I>", 1), "MoveToType"),
        CrclValueError,
        5,
        "XAxis (0.0, 0.0, 0.0) is not a direction",
    ),  # fmt: skip
    (
        "fraction-over-1",
        instance("<CommandID>8</CommandID><Setting>1.5</Setting>", "SetEndEffectorType"),
        CrclValueError,
        8,
        "within 0..1",
    ),  # fmt: skip
    (
        "fraction-negative",
        instance(
            "<CommandID>8</CommandID><TransSpeed xsi:type="
            '"TransSpeedRelativeType"><Fraction>-0.1</Fraction>'
            "</TransSpeed>",
            "SetTransSpeedType",
        ),
        CrclValueError,
        8,
        "TransSpeed/Fraction: -0.1 is out of range",
    ),  # fmt: skip
    (
        "speed-zero",
        instance(
            "<CommandID>8</CommandID><TransSpeed xsi:type="
            '"TransSpeedAbsoluteType"><Setting>0</Setting></TransSpeed>',
            "SetTransSpeedType",
        ),
        CrclValueError,
        8,
        "must be > 0",
    ),  # fmt: skip
    (
        "speed-abstract",
        instance(
            "<CommandID>8</CommandID><TransSpeed><Setting>1</Setting></TransSpeed>",
            "SetTransSpeedType",
        ),
        CrclValueError,
        8,
        "TransSpeed: xsi:type is missing (it must name TransSpeedAbsoluteType,"
        " TransSpeedRelativeType)",
    ),  # fmt: skip
    (
        "negative-dwell",
        instance("<CommandID>9</CommandID><DwellTime>-1</DwellTime>", "DwellType"),
        CrclValueError,
        9,
        "must be >= 0",
    ),  # fmt: skip
    (
        "joint-zero",
        ACTUATE.replace(b"<JointNumber>1<", b"<JointNumber>0<"),
        CrclValueError,
        6,
        "ActuateJoint[1]/JointNumber: 0 is out of range",
    ),  # fmt: skip
    (
        "joint-twice",
        ACTUATE.replace(b"<JointNumber>3<", b"<JointNumber>1<"),
        CrclValueError,
        6,
        "joint 1 appears more than once",
    ),  # fmt: skip
    (
        "joint-speed-negative",
        ACTUATE.replace(b">1.5<", b">-1.5<"),
        CrclValueError,
        6,
        "JointSpeed: -1.5 is out of range",
    ),  # fmt: skip
    (
        "details-unknown",
        ACTUATE.replace(b"JointForceTorqueType", b"JointTorqueType"),
        UnknownCrclType,
        6,
        "JointSpeedAccelType",
    ),  # fmt: skip
    (
        "num-positions",
        THROUGH.replace(b">2</Num", b">3</Num"),
        CrclValueError,
        5,
        "NumPositions is 3 but there are 2",
    ),  # fmt: skip
    (
        "one-waypoint",
        instance(
            "<CommandID>5</CommandID><MoveStraight>0</MoveStraight>"
            + POSE_XML.replace("EndPosition", "Waypoint")
            + "<NumPositions>1</NumPositions>",
            "MoveThroughToType",
        ),
        CrclValueError,
        5,
        "needs at least 2 Waypoint",
    ),  # fmt: skip
    (
        "stop-condition",
        instance("<CommandID>7</CommandID><StopCondition>Slow</StopCondition>", "StopMotionType"),
        CrclValueError,
        7,
        "'Slow' is not one of: Immediate, Fast, Normal",
    ),  # fmt: skip
    (
        "unit-name",
        instance("<CommandID>7</CommandID><UnitName>foot</UnitName>", "SetLengthUnitsType"),
        CrclValueError,
        7,
        "meter, millimeter, inch",
    ),  # fmt: skip
    (
        "joint-reports-order",
        instance(
            "<CommandID>4</CommandID><ResetAll>true</ResetAll>"
            + "".join(
                f"<ConfigureJointReport><JointNumber>{n}</JointNumber><ReportPosition>true"
                "</ReportPosition><ReportTorqueOrForce>false</ReportTorqueOrForce>"
                "<ReportVelocity>false</ReportVelocity></ConfigureJointReport>"
                for n in (3, 1)
            ),
            "ConfigureJointReportsType",
        ),
        CrclValueError,
        4,
        "joint 1 comes after joint 3: joint numbers must be increasing",
    ),  # fmt: skip
]


@pytest.mark.parametrize(
    ("doc", "error", "command_id", "words"), [b[1:] for b in BAD], ids=[b[0] for b in BAD]
)
def test_bad_documents_are_refused(
    doc: bytes, error: type[CrclError], command_id: int | None, words: str
) -> None:
    with pytest.raises(error) as caught:
        parse_command(doc)
    assert isinstance(caught.value, C2rvizError)
    assert caught.value.command_id == command_id
    assert words in str(caught.value)


def test_error_names_the_command_and_where() -> None:
    doc = instance(MOVE.replace("<X>0.5</X>", "<X>abc</X>"), "MoveToType")
    with pytest.raises(CrclValueError) as caught:
        parse_command(doc)
    assert str(caught.value) == (
        "MoveToType (CommandID 5): CRCLCommand/EndPosition/Point/X: 'abc' is not a number "
        "(xs:double, e.g. 0.25 or -1.5e-3)"
    )
    assert caught.value.path == ("CRCLCommand", "EndPosition", "Point", "X")


def test_unknown_type_lists_known_types_briefly() -> None:
    with pytest.raises(UnknownCrclType) as caught:
        parse_command(instance("<CommandID>1</CommandID>", "FlyType"))
    message = str(caught.value)
    assert "one of the 38 CRCL types, e.g. InitCanonType" in message
    assert len(message) < 200
    assert "MoveToType" in caught.value.known and len(caught.value.known) == 38


def test_commands_refuse_bad_values_when_built() -> None:
    with pytest.raises(CrclValueError, match="Setting: 2.0 is out of range"):
        SetEndEffector(command_id=1, setting=2)
    with pytest.raises(CrclValueError, match="CommandID: True is not an integer"):
        GetStatus(command_id=True)
    with pytest.raises(CrclValueError, match="Message: character '\\\\x00' cannot be written"):
        Message(command_id=1, message="a\x00b")
    assert Dwell(command_id=1, seconds=2).seconds == 2.0 and isinstance(
        Dwell(command_id=1, seconds=2).seconds, float
    )
