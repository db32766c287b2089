"""The CRCL door through real sockets: a controller's states, statuses, units and moves.

Documents are written as NIST's samples are (declaration, indentation, namespaced
``xsi:type``); every status read is parsed, validated against CRCLStatus.xsd when
the schemas are at hand, and checked by ``CrclClient``. Motion is judged from what
the world published and the order of statuses, never from how long the test took.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from crcl_support import (
    DONE,
    ERROR,
    READY,
    WORKING,
    CrclClient,
    CrclServerThread,
    actuate,
    command,
    instance,
    move_to,
    pose,
    valid_command,
)
from support import Client

from c2rviz.transports.crcl import pose_to_matrix

REACH = (0.5, 0.0, 0.8)  # tool down: reachable by the motoman from home
OTHER = (0.6, 0.2, 0.6)


def tool_point(server: CrclServerThread) -> np.ndarray:
    return server.call(lambda: server.world.ee_pose().translation.copy())


def started(client: CrclClient) -> CrclClient:
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    return client


def test_ready_then_a_session_init_move_status_end(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    ready = client.ask(100)
    assert ready.command_status.state == READY and ready.command_status.command_id == 0
    assert ready.command_status.status_id == 1
    assert len(ready.joint_statuses.statuses) == 7
    assert all(j.position == 0.0 for j in ready.joint_statuses.statuses)
    assert ready.pose_status.pose.point.z == pytest.approx(1.5)
    assert (ready.settings_status.length_unit, ready.settings_status.angle_unit) == (
        "meter",
        "radian",
    )
    assert ready.gripper_status is None  # the motoman has none

    doc = move_to(2, REACH)
    assert valid_command(doc)
    client.send(command("InitCanon", 1) + doc)
    assert client.until(2).command_status.state == DONE
    assert client.states(1) == [DONE]
    assert client.states(2) == [WORKING, DONE]
    np.testing.assert_allclose(tool_point(crcl_server), REACH, atol=1e-6)
    done = client.ask(101)  # GetStatus reports the latest command, and is not one itself
    assert (done.command_status.command_id, done.command_status.state) == (2, DONE)
    pose_now = pose_to_matrix(done.pose_status.pose)
    np.testing.assert_allclose(pose_now[:3, 3], REACH, atol=1e-6)
    np.testing.assert_allclose(pose_now[:3, 2], (0, 0, -1), atol=1e-6)
    assert client.run(command("EndCanon", 3), 3).command_status.state == DONE
    after = client.run(move_to(4, OTHER), 4).command_status
    assert after.state == ERROR
    assert after.description == "MoveToType (CommandID 4): after EndCanon: send InitCanon first"


def test_nothing_but_init_canon_and_get_status_before_init(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    refused = client.run(move_to(7, REACH), 7).command_status
    assert refused.state == ERROR
    assert refused.description == "MoveToType (CommandID 7): before InitCanon: send InitCanon first"
    assert client.states(7) == [ERROR]
    assert client.run(command("Message", 8, "<Message>hi</Message>"), 8).command_status.state == (
        ERROR
    )
    assert crcl_server.q == (0.0,) * 7


def test_a_straight_move_keeps_the_tool_on_the_line(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    assert client.run(move_to(2, REACH), 2).command_status.state == DONE
    first = crcl_server.call(lambda: len(crcl_server.scene.joints))
    assert client.run(move_to(3, OTHER, straight=True), 3).command_status.state == DONE
    robot = crcl_server.robot
    joints = crcl_server.call(lambda: list(crcl_server.scene.joints[first:]))
    points = np.array([robot.ee_pose(q).translation for q in joints])
    a, b = np.array(REACH), np.array(OTHER)
    along = (points - a) @ (b - a) / np.dot(b - a, b - a)
    off = np.linalg.norm(points - (a + np.outer(along, b - a)), axis=1)
    assert len(points) > 10 and off.max() < 1e-3
    np.testing.assert_allclose(points[-1], OTHER, atol=1e-6)


def test_units_millimeter_and_degree_in_and_out(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    client.send(
        command("SetLengthUnits", 2, "<UnitName>millimeter</UnitName>")
        + command("SetAngleUnits", 3, "<UnitName>degree</UnitName>")
    )
    assert client.until(3).command_status.state == DONE
    mm = tuple(1000.0 * v for v in REACH)
    assert client.run(move_to(4, mm), 4).command_status.state == DONE
    np.testing.assert_allclose(tool_point(crcl_server), REACH, atol=1e-6)
    status = client.ask(5)
    point = status.pose_status.pose.point
    np.testing.assert_allclose((point.x, point.y, point.z), mm, atol=1e-3)
    assert status.settings_status.length_unit == "millimeter"
    assert client.run(actuate(6, {1: 30.0, 7: -45.0}), 6).command_status.state == DONE
    q = crcl_server.q
    assert q[0] == pytest.approx(np.radians(30.0)) and q[6] == pytest.approx(np.radians(-45.0))
    joints = {j.joint_number: j.position for j in client.ask(7).joint_statuses.statuses}
    assert joints[1] == pytest.approx(30.0) and joints[7] == pytest.approx(-45.0)
    limits = client.ask(8).settings_status.joint_limits
    assert limits[0].max_position == pytest.approx(180.0, abs=0.01)  # joint_s: +-3.1416 rad


def test_actuate_joints_numbers_from_one_and_keeps_the_others(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    assert client.run(actuate(2, {2: 0.3, 4: -0.5}), 2).command_status.state == DONE
    assert crcl_server.q == pytest.approx((0.0, 0.3, 0.0, -0.5, 0.0, 0.0, 0.0))
    refused = client.run(actuate(3, {8: 0.1}), 3).command_status
    assert refused.state == ERROR and client.states(3) == [ERROR]
    assert "joint 8 does not exist: motoman_sia20d has joints 1..7" in refused.description
    beyond = client.run(actuate(4, {1: 4.0}), 4).command_status
    assert beyond.state == ERROR and "joint_s (index 0) = 4 rad is outside its limits" in (
        beyond.description
    )
    assert crcl_server.q == pytest.approx((0.0, 0.3, 0.0, -0.5, 0.0, 0.0, 0.0))


def test_joint_speed_caps_the_joint_on_the_clock(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    fastest = []
    for command_id, speed in ((2, None), (3, 0.5)):  # rad/s: under the 50 % default
        target = 0.6 if command_id == 2 else 0.0
        first = crcl_server.call(lambda: len(crcl_server.scene.times))
        client.run(actuate(command_id, {1: target}, speed), command_id)
        times, joints = crcl_server.call(
            lambda f=first: (crcl_server.scene.times[f:], crcl_server.scene.joints[f:])
        )
        q = np.array(joints)[:, 0]
        fastest.append(np.max(np.abs(np.diff(q) / np.diff(times))))
    assert fastest[0] > 0.6  # 50 % of joint_s's 2.26 rad/s is within reach of a 0.6 rad move
    assert fastest[1] <= 0.5 * 1.02  # finite differences of sampled positions


@pytest.mark.wall_clock  # it acts while the move runs: on virtual time the move may end first
def test_a_new_move_takes_over_and_the_old_is_reported(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    client.send(move_to(2, REACH))
    client.until(2, (WORKING,))
    _wait_moving(crcl_server)
    client.send(move_to(3, OTHER))
    assert client.until(3).command_status.state == DONE
    old = [s.command_status for s in client.seen if s.command_status.command_id == 2]
    assert [s.state for s in old] == [WORKING, DONE]
    assert old[-1].description == (
        "MoveToType (CommandID 2): stopped short: taken over by MoveToType (CommandID 3)"
    )
    np.testing.assert_allclose(tool_point(crcl_server), OTHER, atol=1e-6)


@pytest.mark.wall_clock  # it acts while the move runs: on virtual time the move may end first
def test_a_straight_move_brakes_the_one_under_way_first(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    assert client.run(move_to(2, REACH), 2).command_status.state == DONE
    client.send(actuate(3, {1: 1.0}))
    client.until(3, (WORKING,))
    _wait_moving(crcl_server)
    client.send(move_to(4, OTHER, straight=True))
    assert client.until(4).command_status.state == DONE
    assert client.states(3) == [WORKING, DONE]
    np.testing.assert_allclose(tool_point(crcl_server), OTHER, atol=1e-6)


@pytest.mark.wall_clock  # it acts while the move runs: on virtual time the move may end first
def test_stop_motion_brakes_and_reports_both(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    client.send(actuate(2, {1: 2.5}))
    client.until(2, (WORKING,))
    _wait_moving(crcl_server)
    stop = command("StopMotion", 3, "    <StopCondition>Normal</StopCondition>")
    assert client.run(stop, 3).command_status.state == DONE
    assert client.states(2) == [WORKING, DONE]
    assert client.states(3) == [WORKING, DONE]
    q = crcl_server.q
    assert 0.0 < q[0] < 2.5  # at rest, short of its target
    assert not crcl_server.call(lambda: crcl_server.world.moving(crcl_server.world.default))


@pytest.mark.wall_clock
def test_stop_from_the_text_port_is_an_error_naming_it(crcl_server, crcl_connect, connect) -> None:
    client = started(crcl_connect(crcl_server))
    text: Client = connect(crcl_server)
    client.send(actuate(2, {1: 2.5}))
    client.until(2, (WORKING,))
    _wait_moving(crcl_server)
    assert text.ask("stop") == "ok"
    stopped = client.until(2).command_status
    assert stopped.state == ERROR
    assert stopped.description.startswith("ActuateJointsType (CommandID 2): stopped short: motion ")
    assert "stopped by tcp 127.0.0.1:" in stopped.description


@pytest.mark.wall_clock  # it acts while the move runs: on virtual time the move may end first
def test_get_status_is_answered_while_the_arm_moves(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    client.send(actuate(2, {1: 2.5}))
    client.until(2, (WORKING,))
    _wait_moving(crcl_server)
    during = client.ask(50)
    assert (during.command_status.command_id, during.command_status.state) == (2, WORKING)
    velocities = [j.velocity for j in during.joint_statuses.statuses]
    assert velocities[0] is not None and velocities[0] > 0.0  # reported while it moves
    assert client.until(2).command_status.state == DONE


def test_unreachable_and_colliding_moves_move_nothing(crcl_server, crcl_connect, connect) -> None:
    client = started(crcl_connect(crcl_server))
    frames = crcl_server.call(lambda: len(crcl_server.scene.joints))
    far = client.run(move_to(2, (3.0, 0.0, 0.0)), 2).command_status
    assert far.state == ERROR and "MoveToType (CommandID 2): pose unreachable" in far.description
    text = connect(crcl_server)
    assert text.ask("object table box 0.2,0.2,0.2 0.5,0,0.8,0,0,0") == "ok"
    hit = client.run(move_to(3, REACH), 3).command_status
    assert hit.state == ERROR
    assert "would hit table" in hit.description and "link_" in hit.description
    assert crcl_server.call(lambda: len(crcl_server.scene.joints)) == frames
    assert crcl_server.q == (0.0,) * 7


def test_message_shows_in_the_last_commands(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    assert client.run(command("Message", 2, "<Message>hello cell</Message>"), 2)
    lines = crcl_server.call(lambda: list(crcl_server.scene.commands))
    assert "MessageType (CommandID 2): hello cell" in lines
    assert "InitCanonType (CommandID 1)" in lines


@pytest.mark.wall_clock
def test_dwell_works_then_is_done(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    client.send(command("Dwell", 2, "<DwellTime>2</DwellTime>"))
    client.until(2, (WORKING,))
    assert client.ask(3).command_status.state == WORKING
    t0 = crcl_server.call(crcl_server.world.clock.now)
    assert client.until(2).command_status.state == DONE
    assert crcl_server.call(crcl_server.world.clock.now) - t0 > 1.0
    over = client.run(command("Dwell", 4, "<DwellTime>1e9</DwellTime>"), 4).command_status
    assert over.state == ERROR and "over the limit of 3600 s" in over.description


def test_joint_reports_join_the_pushed_statuses(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    assert all(s.joint_statuses is None for s in client.seen)  # compact by default
    assert all(len(raw) < 1024 for raw in client.raw)
    report = """    <ResetAll>true</ResetAll>
    <ConfigureJointReport>
      <JointNumber>2</JointNumber>
      <ReportPosition>true</ReportPosition>
      <ReportTorqueOrForce>false</ReportTorqueOrForce>
      <ReportVelocity>true</ReportVelocity>
    </ConfigureJointReport>"""
    assert client.run(command("ConfigureJointReports", 2, report), 2)
    done = client.run(actuate(3, {2: 0.2}), 3)
    (joint,) = done.joint_statuses.statuses
    assert (joint.joint_number, joint.position, joint.velocity) == (2, pytest.approx(0.2), 0.0)
    (full,) = client.ask(4).joint_statuses.statuses
    assert full.joint_number == 2


def test_documents_back_to_back_and_one_over_many_packets(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    burst = b"".join(
        [
            command("InitCanon", 1),
            instance(
                "SetLengthUnitsType", "<CommandID>2</CommandID><UnitName>inch</UnitName>", "x"
            ),
            command("Message", 3, "<Message>a &lt; b</Message>"),
        ]
    )
    client.send(burst)
    assert client.until(3).command_status.state == DONE
    doc = command("SetAngleUnits", 4, "<UnitName>degree</UnitName>")
    for byte in range(len(doc)):
        client.send(doc[byte : byte + 1])
    assert client.until(4).command_status.state == DONE
    status = client.ask(5).settings_status
    assert (status.length_unit, status.angle_unit) == ("inch", "degree")


def test_program_fields_are_echoed(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    doc = (
        b'<?xml version="1.0" encoding="UTF-8"?>\n'
        b'<CRCLCommandInstance xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">\n'
        b'  <CRCLCommand xsi:type="InitCanonType"><CommandID>1</CommandID></CRCLCommand>\n'
        b"  <ProgramFile>demo.xml</ProgramFile>\n  <ProgramIndex>0</ProgramIndex>\n"
        b"  <ProgramLength>3</ProgramLength>\n</CRCLCommandInstance>"
    )
    assert valid_command(doc)
    status = client.run(doc, 1).command_status
    assert (status.program_file, status.program_index, status.program_length) == ("demo.xml", 0, 3)


def test_speeds_map_to_the_session(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    absolute = '<TransSpeed xsi:type="TransSpeedAbsoluteType"><Setting>0.1</Setting></TransSpeed>'
    relative = '<RotSpeed xsi:type="RotSpeedRelativeType"><Fraction>0.3</Fraction></RotSpeed>'
    assert client.run(command("SetTransSpeed", 2, absolute), 2).command_status.state == DONE
    assert client.run(command("SetRotSpeed", 3, relative), 3).command_status.state == DONE
    settings = client.ask(4).settings_status
    assert settings.trans_speed_absolute.setting == pytest.approx(0.1)
    assert settings.rot_speed_relative.fraction == pytest.approx(0.3)
    fast = '<TransSpeed xsi:type="TransSpeedAbsoluteType"><Setting>50</Setting></TransSpeed>'
    refused = client.run(command("SetTransSpeed", 5, fast), 5).command_status
    assert refused.state == ERROR and "outside 0.001..5 meter/s" in refused.description


def test_a_pose_whose_axes_are_not_orthogonal_is_refused(crcl_server, crcl_connect) -> None:
    client = started(crcl_connect(crcl_server))
    body = "<MoveStraight>false</MoveStraight>" + pose("EndPosition", REACH, (1, 0, 0), (1, 0, 1))
    refused = client.run(command("MoveTo", 2, body), 2).command_status
    assert refused.state == ERROR and "orthogonal" in refused.description
    assert crcl_server.q == (0.0,) * 7


def _wait_moving(server: CrclServerThread) -> None:
    """Until the arm travels and has published a frame since this was called."""
    first = server.call(lambda: len(server.scene.joints))
    moving = server.world.moving
    for _ in range(100_000):
        if server.call(
            lambda: len(server.scene.joints) > first + 1 and moving(server.world.default)
        ):
            return
    raise AssertionError("the arm never moved")


def test_pose_to_matrix_is_what_a_move_reaches(crcl_server, crcl_connect) -> None:
    """The pose a status reports is the one a MoveTo to it reaches (round trip)."""
    client = started(crcl_connect(crcl_server))
    client.run(actuate(2, {1: 0.3, 2: 0.4, 4: -0.8, 6: 0.5}), 2)
    reported = client.ask(3).pose_status.pose
    placement = pin.SE3(pose_to_matrix(reported))
    client.run(actuate(4, {1: 0.0, 2: 0.0, 4: 0.0, 6: 0.0}), 4)
    p, x, z = reported.point, reported.x_axis, reported.z_axis
    back = move_to(5, (p.x, p.y, p.z), x_axis=(x.i, x.j, x.k), z_axis=(z.i, z.j, z.k))
    assert client.run(back, 5).command_status.state == DONE
    assert crcl_server.call(lambda: crcl_server.world.ee_pose()).isApprox(placement, 1e-6)


def test_a_pushed_status_stays_under_1_kib(crcl_server, crcl_connect) -> None:
    """A client reading one status per recv(1024) gets whole ones: long texts are cut."""
    client = crcl_connect(crcl_server)
    doc = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<CRCLCommandInstance xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">\n'
        '  <CRCLCommand xsi:type="MoveToType"><CommandID>1</CommandID>'
        "<MoveStraight>false</MoveStraight>" + pose("EndPosition", (3.0, 0.0, 0.0)) + "\n"
        "  </CRCLCommand>\n  <ProgramFile>" + "p" * 3000 + "</ProgramFile>\n"
        "</CRCLCommandInstance>"
    ).encode()
    refused = client.run(doc, 1).command_status
    assert refused.state == ERROR and refused.program_file == "p" * 240
    assert len(client.raw[-1]) < 1024
