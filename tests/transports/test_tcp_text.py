"""The command language over a real socket, against a real server and robot."""

from __future__ import annotations

import hashlib
import math
import socket
import threading

import numpy as np
import pinocchio as pin
import pytest

import c2rviz
from c2rviz.protocol import replies
from c2rviz.world.observer import MAX_MARKERS

MOTOMAN_LIMITS_DEG = [180.0, 109.4, 169.6, 129.5, 180.0, 109.4, 180.0]


def values(reply: str) -> list[float]:
    """The numbers of an ``ok v0,v1,...`` reply."""
    assert reply.startswith("ok "), reply
    return [float(v) for v in reply[3:].split(",")]


def test_where_starts_at_home(server, connect):
    assert connect(server).ask("where") == "ok 0,0,0,0,0,0,0"


def test_the_issue_example(server, connect):
    client = connect(server)
    client.send("degrees\nmove 0,1 90,90\nwhere\nmove 9 1\nwhere\n")
    got = [client.read_line() for _ in range(5)]
    assert got[:3] == ["ok", "ok", "ok 90,90,0,0,0,0,0"]
    assert got[3] == "error: joint index 9 out of range: motoman_sia20d has joints 0..6"
    assert got[4] == "ok 90,90,0,0,0,0,0"


def test_seed_motoman_script_step_by_step(server, connect):
    """The seed's motoman.txt, checked with ``where`` after every step."""
    client = connect(server)
    steps = [
        ("sleep 0.01", None),
        ("degree", None),
        ("home", [0] * 7),
        ("rand", "random"),
        ("move 0 90.0", "first=90"),
        ("move 0 -90.0", "first=-90"),
        ("j 45,45,45,45,45,45,45", [45] * 7),
        ("joints 0,0,0,0,0,0,0", [0] * 7),
        ("move 0,1 90,90", [90, 90, 0, 0, 0, 0, 0]),
        ("move 0,1 -90,-90", [-90, -90, 0, 0, 0, 0, 0]),
    ]
    before = None
    for line, expected in steps:
        assert client.ask(line) == "ok", line
        where = values(client.ask("where"))
        if expected == "random":
            assert all(-lim <= v <= lim for v, lim in zip(where, MOTOMAN_LIMITS_DEG))
            assert where != [0.0] * 7
        elif isinstance(expected, str):
            assert where[0] == pytest.approx(float(expected.split("=")[1]))
            assert where[1:] == pytest.approx(before[1:]), "move 0 changed another joint"
        elif expected is not None:
            assert where == pytest.approx(expected)
        before = where


def test_rand_stays_within_limits_every_time(server, connect):
    client = connect(server)
    robot = server.robot
    for _ in range(200):
        assert client.ask("rand") == "ok"
        q = values(client.ask("where"))
        assert all(lo <= v <= hi for v, lo, hi in zip(q, robot.lower, robot.upper))


def test_units_are_per_connection(server, connect):
    deg, rad = connect(server), connect(server)
    assert deg.ask("degrees") == "ok"
    assert deg.ask("move 2 90") == "ok"
    assert values(rad.ask("where"))[2] == pytest.approx(math.pi / 2)
    assert rad.ask("move 2 -0.5") == "ok"
    assert values(deg.ask("where"))[2] == pytest.approx(math.degrees(-0.5))
    assert rad.ask("radian") == "ok" and deg.ask("degree") == "ok"
    assert values(deg.ask("where"))[2] == pytest.approx(math.degrees(-0.5))


def test_limits_are_checked_in_the_clients_units(server, connect):
    client = connect(server)
    assert client.ask("degrees") == "ok"
    assert client.ask("move 1 120") == (
        "error: joint_l (index 1) = 120 deg is outside its limits -109.4349389..109.4349389 deg"
    )
    assert client.ask("radians") == "ok"
    assert client.ask("move 1 2") == (
        "error: joint_l (index 1) = 2 rad is outside its limits -1.91..1.91 rad"
    )
    assert server.q == (0.0,) * 7


def test_a_value_read_back_at_a_limit_is_accepted(server, connect):
    client = connect(server)
    client.ask("degrees")
    upper = math.degrees(1.91)
    assert client.ask(f"move 1 {upper:.10g}") == "ok"
    assert server.q[1] == pytest.approx(1.91)
    assert client.ask("joints " + client.ask("where")[3:]) == "ok"


def test_failed_commands_change_nothing(server, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask("joints 10,20,30,40,50,60,70")
    before = server.q
    for bad in [
        "joints 1,2,3,4,5,6",
        "joints 1,2,3,4,5,6,7,8",
        "joints 1,2,3,4,5,6,700",
        "move 0,1 10,500",
        "move 0,9 10,10",
        "move 0,0 1,2",
        "move 0,1 90",
        "j 1,2,3,nan,5,6,7",
    ]:
        assert client.ask(bad).startswith("error: "), bad
        assert server.q == before, bad


def test_move_sets_only_the_listed_joints(server, connect):
    client = connect(server)
    client.ask("joints 0.1,0.2,0.3,0.4,0.5,0.6,0.7")
    assert client.ask("move 6,0 -0.5,0.5") == "ok"
    assert values(client.ask("where")) == pytest.approx([0.5, 0.2, 0.3, 0.4, 0.5, 0.6, -0.5])


def test_pose_is_pinocchio_fk(server, connect):
    client = connect(server)
    assert values(client.ask("pose")) == pytest.approx([0, 0, 1.5, 0, 0, 0], abs=1e-12)
    q = [0.3, -0.4, 0.5, 1.0, -0.7, 0.2, 0.9]
    client.ask("joints " + ",".join(map(str, q)))
    expected = server.robot.ee_pose(q)
    x, y, z, roll, pitch, yaw = values(client.ask("pose"))
    assert [x, y, z] == pytest.approx(expected.translation, abs=1e-9)
    assert pin.rpy.rpyToMatrix(roll, pitch, yaw) == pytest.approx(expected.rotation, abs=1e-8)
    client.ask("degrees")
    deg = values(client.ask("pose"))
    assert deg[3:] == pytest.approx(np.degrees([roll, pitch, yaw]), abs=1e-7)


def test_limits_in_the_clients_units(server, connect):
    client = connect(server)
    assert client.ask("limits") == (
        "ok -3.1416..3.1416 rad,-1.91..1.91 rad,-2.96..2.96 rad,-2.26..2.26 rad,"
        "-3.1416..3.1416 rad,-1.91..1.91 rad,-3.1416..3.1416 rad"
    )
    client.ask("degrees")
    first = client.ask("limits")[3:].split(",")[1]
    assert first == f"{-math.degrees(1.91):.10g}..{math.degrees(1.91):.10g} deg"


def test_names_help_and_unknown(server, connect):
    client = connect(server)
    assert client.ask("names") == (
        "ok motoman_sia20d joint_s,joint_l,joint_e,joint_u,joint_r,joint_b,joint_t"
    )
    assert client.ask("help") == replies.help_reply()
    digest = hashlib.sha256(server.robot.source.xml.encode()).hexdigest()[:12]
    assert client.ask("version") == f"ok c2rviz {c2rviz.__version__} robot.urdf sha256:{digest}"
    assert client.ask("fly") == "error: unknown command 'fly' (try 'help')"
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"


def test_markers_reach_the_scene(server, connect):
    client = connect(server)
    assert client.ask("marker cube") == "ok"
    assert client.ask("rgb 0,255,0") == "ok"
    assert client.ask("mark") == "ok"
    assert client.ask("color 0,0,1") == "ok"
    assert client.ask("mark 0.5,0,0.2,0,0,1.5707963267948966") == "ok"
    markers = server.call(lambda: list(server.scene.markers))
    assert [m.shape for m in markers] == ["cube", "cube"]
    assert markers[0].rgb == (0.0, 1.0, 0.0) and markers[1].rgb == (0.0, 0.0, 1.0)
    assert markers[0].position == pytest.approx((0, 0, 1.5))
    assert markers[1].position == pytest.approx((0.5, 0, 0.2))
    assert markers[1].wxyz == pytest.approx((math.sqrt(0.5), 0, 0, math.sqrt(0.5)))
    assert client.ask("move 0 1") == "ok"
    assert client.ask("clear") == "ok"
    assert server.call(lambda: list(server.scene.markers)) == []
    assert server.q == (0.0,) * 7


def test_markers_are_bounded_oldest_first(server, connect):
    client = connect(server)
    client.send("".join(f"mark {k / 1000},0,0,0,0,0\n" for k in range(MAX_MARKERS + 5)))
    assert all(client.read_line() == "ok" for _ in range(MAX_MARKERS + 5))
    markers = server.call(lambda: list(server.world.markers))
    assert len(markers) == MAX_MARKERS
    assert markers[0].position[0] == pytest.approx(5 / 1000)


def test_marker_style_is_per_connection(server, connect):
    a, b = connect(server), connect(server)
    assert a.ask("marker arrow") == "ok" and a.ask("color 0,0,1") == "ok"
    assert b.ask("mark") == "ok"
    (marker,) = server.call(lambda: list(server.scene.markers))
    assert (marker.shape, marker.rgb) == ("sphere", (1.0, 0.0, 0.0))


def test_every_state_change_reaches_the_scene(server, connect):
    client = connect(server)
    for line in ["home", "rand", "joints 1,1,1,1,1,1,1", "move 0 0", "clear"]:
        client.ask(line)
    shown = server.call(lambda: list(server.scene.joints))
    assert len(shown) == 5
    assert shown[-1] == (0.0,) * 7
    assert shown[2] == (1.0,) * 7


@pytest.mark.wall_clock
def test_sleep_pauses_only_its_own_connection(server, connect):
    sleeper, other = connect(server), connect(server)
    sleeper.send("sleep 0.5\nmove 0 1\n")
    assert other.ask("move 0 -1") == "ok"  # answered while the sleeper sleeps
    assert sleeper.read_line() == "ok"
    assert sleeper.read_line() == "ok"
    assert server.q[0] == 1.0  # the sleeper's line ran after the other's


def test_comments_blank_lines_and_crlf(server, connect):
    client = connect(server)
    client.send("\n   \n# only a comment\r\nHOME  # to zero\r\n  move 0 ,1   0.1 , 0.2\r\n")
    assert client.read_line() == "ok"
    assert client.read_line() == "ok"
    assert values(client.ask("where"))[:2] == pytest.approx([0.1, 0.2])


def test_bye_closes_only_this_connection(server, connect):
    a, b = connect(server), connect(server)
    assert a.ask("bye") == replies.BYE
    assert a.closed_by_server()
    assert b.ask("where") == "ok 0,0,0,0,0,0,0"


def test_quit_stops_the_program_cleanly(c2rviz_process):
    proc = c2rviz_process("--no-viewer")
    with socket.create_connection(("127.0.0.1", proc.port), timeout=10) as sock:
        sock.sendall(b"quit\n")
        assert sock.makefile().readline() == "ok\n"
    assert proc.wait(timeout=10) == 0
    with socket.socket() as probe:  # a new server can listen on the port again
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        probe.bind(("127.0.0.1", proc.port))
        probe.listen()


def test_many_clients_share_one_robot(server, connect):
    clients = [connect(server) for _ in range(10)]
    errors: list[str] = []

    def drive(client, index):
        for k in range(50):
            reply = client.ask(f"move {index % 7} {k / 100}")
            if reply != "ok":
                errors.append(reply)

    threads = [threading.Thread(target=drive, args=(c, i)) for i, c in enumerate(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert server.q == pytest.approx([0.49] * 7)


RUNS = {
    "plain": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1", "j 0.2,0.2,0.3,0.1,0.2,0.3,0.2"] * 50,
    "crlf": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1\r", "j 0.3,0,0,0,0,0,0\r"] * 20,
    "bad-in-the-middle": [
        "joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1",
        "joints 0.1,0.2,0.3",  # too few
        "joints 0.1,9,0.3,0.1,0.2,0.3,0.1",  # joint_l past its limit
        "joints 0.1,0.2,,0.1,0.2,0.3,0.1",  # empty value
        "joints 0.1,0.2,nan,0.1,0.2,0.3,0.1",
        "j 1e309,0,0,0,0,0,0",
        "joints 0.5,0.5,0.5,0.5,0.5,0.5,0.5",
    ],
    "at-the-limit": ["joints 0,1.910000001,0,0,0,0,0", "joints 0,-1.91,0,0,0,0,0"],
    "counts-that-add-up": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1,0.1", "j 0.1,0.2,0.3,0.1,0.2,0.3"],
    "cr-inside": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1\r", "joints 0.1,0.2\r,0.3,0.1,0.2,0.3,0.1"],
    "past-a-limit-late": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1"] * 5
    + ["joints 0.1,0.2,0.3,0.1,0.2,0.3,-4", "joints 0,-9,0,0,0,0,0", "j 0,0,0,0,0,0,0"],
    "mixed": ["joints 0.1,0.2,0.3,0.1,0.2,0.3,0.1", "where", "j 0.2,0,0,0,0,0,0", "move 0 0.4"]
    + ["joints 0.1,0.1,0.1,0.1,0.1,0.1,0.1"] * 3
    + ["JOINTS 0.2,0,0,0,0,0,0", "joints  0.3,0,0,0,0,0,0", "joints 0.4,0,0,0,0,0,0 # note"],
}


@pytest.mark.parametrize("name", list(RUNS))
def test_runs_of_joints_lines_answer_as_line_by_line(server, connect, name):
    """Plain joints lines read together are checked as one batch and only the last is
    shown; every reply, error and the final state equal running them one by one."""
    from c2rviz.session import Services, Session
    from c2rviz.world.world import World

    shadow = Session(Services(World(server.robot)))
    expected = []
    for line in RUNS[name]:
        try:
            expected.append(shadow.run(line))
        except c2rviz.C2rvizError as exc:
            expected.append(replies.error(exc))
    client = connect(server)
    frames_before = server.call(lambda: len(server.scene.joints))
    client.send("".join(line + "\n" for line in RUNS[name]))
    assert [client.read_line() for _ in expected] == expected
    assert server.q == shadow.world.q
    noted = server.call(lambda: len(server.scene.commands) + len(server.scene.refused))
    assert noted >= len(RUNS[name])
    if name == "plain":  # one batch of 100 lines: far fewer states shown than lines
        assert server.call(lambda: len(server.scene.joints)) - frames_before < len(RUNS[name])


@pytest.mark.parametrize("last", ["where", "joints 0.1,0,0,0,0,0,0\r", "sleep 0.2"])
def test_a_last_line_without_a_newline_is_answered_at_eof(server, last):
    """Issue 23.11: `printf 'where' | nc -q1 host 31000` gets its reply, then the close."""
    sock = socket.create_connection((server.host, server.port), timeout=60)
    with sock:
        sock.sendall(b"degrees\n" + last.encode())
        sock.shutdown(socket.SHUT_WR)
        data = b""
        while chunk := sock.recv(4096):
            data += chunk
    lines = data.decode().splitlines()
    assert lines[0] == "ok" and len(lines) == 2, lines
    assert lines[1] == ("ok 0,0,0,0,0,0,0" if last == "where" else "ok")
