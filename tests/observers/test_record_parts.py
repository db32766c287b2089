"""A recorded pick and place replays to the same final part poses: NAME.txt carries the
workcell, the parts and the gripper's openings."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import Client, ServerLimits, ServerThread, load_robot

from c2rviz.clients import player
from c2rviz.world.virtual_clock import VirtualClock

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # the fanuc pointing down at the part (test_part_verbs)
LIFT = "0,0,0,0,-1.5707963,0"
AWAY = "1.2,0,0,0,-1.5707963,0"
AXES = ("x", "y", "z", "roll", "pitch", "yaw")
SETUP = [  # before the recording: NAME.txt starts with them
    "grip 1",
    "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
    "part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0 type=block",
    "part p2 sphere 0.02 0.5,0.2,0.199",
]
RUN = [
    "part p3 cylinder 0.02,0.05 0.5,-0.2,0.204,0,0,0.3 color=0.2,0.4,0.6",
    "sleep 0.5",
    f"joints {PICK}",
    "grip 0",
    "sleep 0.5",
    f"joints {LIFT}",
    f"joints {AWAY}",
    "grip 1",
    "sleep 1",
    "part p2 remove",
]


def _server(tmp_path: Path) -> ServerThread:
    robot = load_robot("fanuc_lrmate200id")
    return ServerThread(robot, ServerLimits(), clock=VirtualClock(), record_dir=tmp_path).start()


def test_a_recorded_pick_and_place_replays_to_the_same_part_poses(tmp_path: Path) -> None:
    first = _server(tmp_path)
    client = Client(first.host, first.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record take").startswith("ok recording take")
        for line in RUN:
            assert client.ask(line).startswith("ok"), line
        final = client.ask("parts")
        assert final.startswith("ok p1:") and ":resting on floor;p3:" in final, final
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        first.stop()
    text = (tmp_path / "take.txt").read_text()
    assert "object table box " in text and "part p1 box " in text and "grip 1.0" in text
    assert "part p2 remove" in text
    rows = (tmp_path / "take.csv").read_text().splitlines()
    header, last = rows[0].split(","), rows[-1].split(",")
    assert header[-12:] == [f"{p}.{a}" for p in ("p1", "p2") for a in AXES]
    assert float(last[header.index("p1.z")]) == pytest.approx(0.085, abs=1e-6)  # on the floor
    assert last[-6:] == [""] * 6  # p2 was removed
    lifted = max(float(row.split(",")[header.index("p1.z")]) for row in rows[1:])
    assert lifted > 0.4  # carried up
    (tmp_path / "replay").mkdir()
    second = _server(tmp_path / "replay")
    try:
        assert player.main([str(tmp_path / "take.txt"), "--port", str(second.port)]) == 0
        replayed = Client(second.host, second.port)
        try:
            assert replayed.ask("sleep 1") == "ok"
            assert replayed.ask("parts") == final
        finally:
            replayed.close()
    finally:
        second.stop()


def test_the_bag_has_each_part_as_a_tf_frame_and_a_marker(tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    server = _server(tmp_path)
    client = Client(server.host, server.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record take").startswith("ok recording take")
        for line in RUN:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        server.stop()
    frames: dict[str, list[tuple[str, tuple[float, float, float]]]] = {}
    marked: list[tuple[str, int]] = []
    with AnyReader([tmp_path / "take"]) as reader:
        for conn, _, raw in reader.messages():
            message = reader.deserialize(raw, conn.msgtype)
            if conn.topic == "/tf":
                for x in message.transforms:
                    t = x.transform.translation
                    frames.setdefault(x.child_frame_id, []).append(
                        (x.header.frame_id, (t.x, t.y, t.z))
                    )
            elif conn.topic.endswith("visualization_marker_array"):
                marked += [(m.ns, m.action) for m in message.markers if m.ns == "parts"]
    assert {"parts/p1", "parts/p2", "parts/p3"} <= set(frames)
    parent, (x, y, z) = frames["parts/p1"][-1]
    assert parent == "base_link" and z == pytest.approx(0.085, abs=1e-6)  # on the floor
    heights = [where[2] for _, where in frames["parts/p1"]]
    assert max(heights) > 0.4 and len(heights) > 20  # carried up, falling: frame by frame
    assert marked.count(("parts", 0)) == 3 and marked.count(("parts", 2)) == 1  # p2 deleted


def test_a_recording_replays_its_cameras_and_the_bag_keeps_their_reports(tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    server = _server(tmp_path)
    client = Client(server.host, server.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("camera top 0.45,0,1.2,0,1.5707963267948966,0") == "ok"
        assert client.ask("record take").startswith("ok recording take")
        assert client.ask("camera top rate 4") == "ok"
        assert client.ask("camera side 0.45,-1,0.2,0,0,1.5707963267948966 1,1,3") == "ok"
        assert client.ask("sleep 1") == "ok"
        assert client.ask("camera side remove") == "ok"
        seen = client.ask("camera top")
        assert seen.startswith("ok p1:block:")
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        server.stop()
    text = (tmp_path / "take.txt").read_text()
    assert "camera top 0.45,0.0,1.2,0.0,1.5707963267948966,0.0 " in text
    assert "camera top rate 4.0" in text and "camera side remove" in text
    reports: dict[str, list[tuple[float, int]]] = {}
    with AnyReader([tmp_path / "take"]) as reader:
        for conn, _, raw in reader.messages():
            if conn.topic.startswith("/c2rviz/cameras/"):
                message = reader.deserialize(raw, conn.msgtype)
                assert conn.msgtype == "geometry_msgs/msg/PoseArray"
                assert message.header.frame_id == "cameras/" + conn.topic.rsplit("/", 1)[1]
                stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
                reports.setdefault(conn.topic, []).append((round(stamp, 6), len(message.poses)))
    top = reports["/c2rviz/cameras/top"]
    assert [t for t, _ in top[:5]] == [0.0, 0.0, 0.25, 0.5, 0.75]  # at 10 Hz, then at 4
    assert all(n == 2 for _, n in top)  # p1 and p2 on the table below
    assert reports["/c2rviz/cameras/side"][0][0] == 0.0
    (tmp_path / "replay").mkdir()
    second = _server(tmp_path / "replay")
    try:
        assert player.main([str(tmp_path / "take.txt"), "--port", str(second.port)]) == 0
        replayed = Client(second.host, second.port)
        try:
            assert replayed.ask("cameras").startswith("ok top:0.45,0,1.2,0,1.570796327,0:")
            assert replayed.ask("camera top") == seen
        finally:
            replayed.close()
    finally:
        second.stop()
