"""Every CRCL command type gets an answer (issue 24), and the gripper through CRCL.

The fanuc has a gripper, the motoman none. Each command is written by the codec
(checked against NIST's CRCLCommandInstance.xsd when the schemas are at hand) and
sent in a canon session; what c2rviz does with it is its final state and, for a
refusal, words of the why: the table of docs/crcl.md.
"""

from __future__ import annotations

import pytest
from crcl_support import DONE, ERROR, WORKING, CrclClient, command, valid_command

from c2rviz.transports.crcl import (
    COMMAND_TYPES,
    ActuateJoint,
    ActuateJoints,
    CloseToolChanger,
    Command,
    ConfigureJointReport,
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
    Guard,
    InitCanon,
    JointForceTorque,
    JointPositionsTolerances,
    JointPositionTolerance,
    JointSpeedAccel,
    LoopBlockEnd,
    LoopBlockStart,
    Message,
    MoveScrew,
    MoveThroughTo,
    MoveTo,
    OpenToolChanger,
    ParameterSetting,
    Point,
    Pose,
    PoseTolerance,
    RotAccelAbsolute,
    RotSpeedAbsolute,
    RunProgram,
    SetAngleUnits,
    SetDefaultJointPositionsTolerances,
    SetEndEffector,
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
    StopMotion,
    TransAccelAbsolute,
    TransSpeedRelative,
    Vector,
    write_command,
)

HOME_TOOL = Pose(Point(0.465, 0.0, 0.695), Vector(0.0, 0.0, 1.0), Vector(-1.0, 0.0, 0.0))
"""The fanuc's link_6 at home: its x axis along the base's x (the flange normal)."""
TOLERANCE = PoseTolerance(0.001, 0.001, 0.001, 0.01, 0.01)
PARAMETER = ParameterSetting("force", "10")

# command -> final state, words of the description (None: say nothing particular)
ANSWERS: list[tuple[Command, str, str | None]] = [
    (MoveTo(command_id=2, move_straight=False, end_position=HOME_TOOL), DONE, None),
    (MoveTo(command_id=3, move_straight=True, end_position=HOME_TOOL), DONE, None),
    (
        MoveThroughTo(
            command_id=4, move_straight=False, waypoints=(HOME_TOOL, HOME_TOOL), num_positions=2
        ),
        DONE,
        None,
    ),
    (
        MoveScrew(command_id=5, axial_distance_screw=0.01, turn=1.0),
        ERROR,
        "screw motions are not supported",
    ),
    (
        ActuateJoints(
            command_id=6,
            joints=(ActuateJoint(joint_number=6, position=0.1, details=JointSpeedAccel()),),
        ),
        DONE,
        None,
    ),
    (
        ActuateJoints(
            command_id=7,
            joints=(
                ActuateJoint(joint_number=6, position=0.1, details=JointForceTorque(setting=1.0)),
            ),
        ),
        ERROR,
        "force or torque control is not simulated",
    ),
    (StopMotion(command_id=8, condition="Immediate"), DONE, None),
    (Dwell(command_id=9, seconds=0.05), DONE, None),
    (Message(command_id=10, message="hello"), DONE, None),
    (SetLengthUnits(command_id=11, unit="meter"), DONE, None),
    (SetAngleUnits(command_id=12, unit="radian"), DONE, None),
    (SetForceUnits(command_id=13, unit="pound"), DONE, "no forces or torques"),
    (SetTorqueUnits(command_id=14, unit="footPound"), DONE, "no forces or torques"),
    (SetTransSpeed(command_id=15, speed=TransSpeedRelative(0.8)), DONE, None),
    (SetTransAccel(command_id=16, accel=TransAccelAbsolute(2.0)), DONE, "accelerations follow"),
    (SetRotSpeed(command_id=17, speed=RotSpeedAbsolute(1.0)), DONE, "kept"),
    (SetRotAccel(command_id=18, accel=RotAccelAbsolute(2.0)), DONE, "accelerations follow"),
    (SetEndPoseTolerance(command_id=19, tolerance=TOLERANCE), DONE, "within 0.1 mm"),
    (SetIntermediatePoseTolerance(command_id=20, tolerance=TOLERANCE), DONE, "within 0.1 mm"),
    (
        SetDefaultJointPositionsTolerances(
            command_id=21,
            joint_tolerances=JointPositionsTolerances((JointPositionTolerance(1, 0.01),)),
        ),
        DONE,
        "joints exactly",
    ),
    (
        ConfigureJointReports(
            command_id=22,
            reset_all=False,
            reports=(
                ConfigureJointReport(
                    joint_number=1,
                    report_position=True,
                    report_torque_or_force=False,
                    report_velocity=True,
                ),
            ),
        ),
        DONE,
        None,
    ),
    (
        ConfigureStatusReport(
            command_id=23,
            report_joint_statuses=True,
            report_pose_status=True,
            report_gripper_status=True,
            report_settings_status=True,
            report_sensors_status=False,
            report_guards_status=False,
        ),
        DONE,
        None,
    ),
    (SetEndEffector(command_id=24, setting=1.0), DONE, None),
    (SetEndEffectorParameters(command_id=25, parameters=(PARAMETER,)), DONE, "no parameters"),
    (OpenToolChanger(command_id=26), ERROR, "no tool changer"),
    (CloseToolChanger(command_id=27), ERROR, "no tool changer"),
    (SetMotionCoordination(command_id=28, coordinated=True), DONE, None),
    (EnableGripper(command_id=29, gripper_name="gripper_hand"), DONE, None),
    (EnableGripper(command_id=30, gripper_name="suction"), ERROR, "no gripper 'suction'"),
    (DisableGripper(command_id=31, gripper_name="gripper_hand"), DONE, None),
    (SetEndEffector(command_id=32, setting=0.0), ERROR, "the gripper is disabled"),
    (EnableGripper(command_id=33, gripper_name="gripper_hand"), DONE, None),
    (EnableSensor(command_id=34, sensor_id="ati"), ERROR, "no sensor 'ati'"),
    (DisableSensor(command_id=35, sensor_id="ati"), ERROR, "no sensor 'ati'"),
    (SetRobotParameters(command_id=36, parameters=(PARAMETER,)), ERROR, "no robot parameters"),
    (EnableRobotParameterStatus(command_id=37, parameter_name="x"), ERROR, "robot parameters"),
    (DisableRobotParameterStatus(command_id=38, parameter_name="x"), ERROR, "robot parameters"),
    (RunProgram(command_id=39, program_text="MOVJ P1"), ERROR, "no native programs"),
    (LoopBlockStart(command_id=40, loop_name="a"), ERROR, "loop blocks are not supported"),
    (LoopBlockEnd(command_id=41, loop_name="a", max_count=2), ERROR, "loop blocks"),
    (
        Message(
            command_id=42,
            message="guarded",
            guards=(Guard(sensor_id="ati", limit_type="OVER_MAX", limit_value=5.0),),
        ),
        ERROR,
        "guards need sensors",
    ),
    (EndCanon(command_id=43), DONE, None),
    (InitCanon(command_id=44), DONE, None),
]


def test_the_table_holds_every_command_type() -> None:
    answered = {type(c) for c, _, _ in ANSWERS} | {GetStatus}
    assert answered == set(COMMAND_TYPES)


def test_every_command_type_is_answered(start_crcl, crcl_connect) -> None:
    server = start_crcl("fanuc_lrmate200id")
    client: CrclClient = crcl_connect(server)
    assert client.run(write_command(InitCanon(command_id=1)), 1).command_status.state == DONE
    for sent, state, words in ANSWERS:
        doc = write_command(sent)
        assert valid_command(doc), type(sent).__name__
        got = client.run(doc, sent.command_id).command_status
        name = type(sent).__name__
        assert got.state == state, (name, got.description)
        if words is not None:
            assert words in got.description, (name, got.description)
            assert got.description.startswith(f"{sent.XSI_TYPE} (CommandID {sent.command_id}): ")
    assert server.opening() == 1.0


def test_set_end_effector_moves_the_fingers_and_reports_them(start_crcl, crcl_connect) -> None:
    server = start_crcl("fanuc_lrmate200id")
    client = crcl_connect(server)
    client.send(
        command("InitCanon", 1) + command("SetLengthUnits", 2, "<UnitName>millimeter</UnitName>")
    )
    client.until(2)
    closed = client.ask(3)
    assert closed.gripper_status.gripper_name == "gripper_hand"
    assert closed.gripper_status.separation == 0.0
    assert closed.settings_status.end_effector_setting == 0.0
    assert client.run(command("SetEndEffector", 4, "<Setting>1</Setting>"), 4)
    assert client.states(4) == [WORKING, DONE]
    opened = client.ask(5)
    assert opened.gripper_status.separation == pytest.approx(60.0)  # mm
    assert opened.settings_status.end_effector_setting == 1.0
    openings = server.call(lambda: [o for o, _ in server.scene.openings])
    assert openings[-1] == 1.0 and len(openings) > 2  # travelled, on the world's clock
    client.send(command("SetEndEffector", 6, "<Setting>0</Setting>"))
    client.until(6, (WORKING,))
    client.send(command("SetEndEffector", 7, "<Setting>0.5</Setting>"))
    assert client.until(7).command_status.state == DONE
    assert client.states(6)[-1] == DONE  # taken over, reported
    assert server.opening() == 0.5


def test_a_robot_without_a_gripper_says_no_gripper(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    client.send(command("InitCanon", 1) + command("SetEndEffector", 2, "<Setting>1</Setting>"))
    refused = client.until(2).command_status
    assert refused.state == ERROR
    assert refused.description.startswith("SetEndEffectorType (CommandID 2): no gripper")
    assert client.ask(3).gripper_status is None
