"""Bags written by BagWriter, read back with rosbags' AnyReader and with the mcap package."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from ros_helpers import bundled
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability
from test_ros_tf_tree import close, link_poses

from c2rviz.ros import messages as m
from c2rviz.ros import messages as mk
from c2rviz.ros.bag_writer import BagRobot, BagWriter
from c2rviz.ros.errors import BagError, MessageError

FRAMES = 150
LATCHED = {
    "/tf_static",
    "/robot_description",
    "/left/robot_description",
    "/right/robot_description",
}


def record_one(path: Path) -> tuple[list[tuple[float, list[float]]], BagRobot]:
    """A recording of the motoman: frames at 100 Hz, commands, replies and markers."""
    robot = bundled("motoman_sia20d")
    rng = np.random.default_rng(5)
    states = [(i * 0.01, robot.random(rng)) for i in range(FRAMES)]
    with BagWriter(path) as writer:
        arm = BagRobot(writer, robot)
        arm.start(0.0)
        for t, q in states:
            arm.frame(t, q, [0.1] * robot.n if t > 0.5 else ())
            if t in (0.0, 1.0):
                writer.text("/c2rviz/commands", t, f"tcp:1 joints {q}")
                writer.text("/c2rviz/replies", t, "ok")
        marker = mk.marker(
            0.2, "base_link", "markers", 0, mk.SPHERE, (0.5, 0, 0.3), scale=(0.02,) * 3
        )
        writer.markers(0.2, mk.marker_array([marker]))
        writer.markers(1.2, mk.marker_array([mk.delete_marker(1.2, "base_link", "markers", 0)]))
        assert not writer.closed and writer.error is None
    assert writer.closed and writer.error is None
    return states, arm


def read_all(path: Path) -> tuple[AnyReader, dict[str, list[tuple[int, Any]]]]:
    by_topic: dict[str, list[tuple[int, Any]]] = {}
    with AnyReader([path]) as reader:
        for conn, log_ns, raw in reader.messages():
            by_topic.setdefault(conn.topic, []).append(
                (log_ns, reader.deserialize(raw, conn.msgtype))
            )
    return reader, by_topic


def test_one_robot_reads_back_with_rosbags(tmp_path: Path) -> None:
    states, arm = record_one(tmp_path / "rec")
    robot, tree = arm.robot, arm.tree
    assert sorted(p.name for p in (tmp_path / "rec").iterdir()) == ["metadata.yaml", "rec.mcap"]
    with AnyReader([tmp_path / "rec"]) as reader:
        types = {name: info.msgtype for name, info in reader.topics.items()}
        durability = {
            c.topic: c.ext.offered_qos_profiles[0].durability  # type: ignore[union-attr]
            for c in reader.connections
        }
    assert types == {
        "/robot_description": "std_msgs/msg/String",
        "/tf_static": "tf2_msgs/msg/TFMessage",
        "/joint_states": "sensor_msgs/msg/JointState",
        "/tf": "tf2_msgs/msg/TFMessage",
        "/c2rviz/commands": "std_msgs/msg/String",
        "/c2rviz/replies": "std_msgs/msg/String",
        "/visualization_marker_array": "visualization_msgs/msg/MarkerArray",
    }
    for topic, value in durability.items():
        latched = QosDurability.TRANSIENT_LOCAL if topic in LATCHED else QosDurability.VOLATILE
        assert value == latched, topic
    _, by_topic = read_all(tmp_path / "rec")
    assert by_topic["/robot_description"][0][1].data == robot.source.xml
    ((_, static),) = by_topic["/tf_static"]
    statics = [
        (
            s.header.frame_id,
            s.child_frame_id,
            (s.transform.translation.x, s.transform.translation.y, s.transform.translation.z),
            (
                s.transform.rotation.x,
                s.transform.rotation.y,
                s.transform.rotation.z,
                s.transform.rotation.w,
            ),
        )
        for s in static.transforms
    ]
    joint_states, tfs = by_topic["/joint_states"], by_topic["/tf"]
    assert len(joint_states) == len(tfs) == FRAMES
    for (t, q), (js_ns, js), (tf_ns, tf) in zip(states, joint_states, tfs):
        stamp = m.nanoseconds(t)
        assert js_ns == tf_ns == stamp  # log time is the frame's time...
        assert (
            js.header.stamp.sec * 10**9 + js.header.stamp.nanosec == stamp
        )  # ...and so is the stamp
        assert tuple(js.name) == tree.names
        assert js.position.tolist() == tree.joint_positions(robot.configuration(q))[1]
        assert np.allclose(js.position[: robot.n], q, rtol=0, atol=1e-9)
        assert js.velocity.tolist() == ([0.1] * robot.n if t > 0.5 else [])
        moving = [
            (
                x.header.frame_id,
                x.child_frame_id,
                (x.transform.translation.x, x.transform.translation.y, x.transform.translation.z),
                (
                    x.transform.rotation.x,
                    x.transform.rotation.y,
                    x.transform.rotation.z,
                    x.transform.rotation.w,
                ),
            )
            for x in tf.transforms
        ]
        assert all(
            x.header.stamp.sec * 10**9 + x.header.stamp.nanosec == stamp for x in tf.transforms
        )
        poses = link_poses(robot.base, statics + moving)
        assert close(poses[robot.eelink], robot.ee_pose(q))
    stamps = [ns for ns, _ in joint_states]
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)
    assert [x.data for _, x in by_topic["/c2rviz/replies"]] == ["ok", "ok"]
    markers = [x.markers[0] for _, x in by_topic["/visualization_marker_array"]]
    assert [(x.action, x.type, x.ns, x.id) for x in markers] == [
        (0, mk.SPHERE, "markers", 0),
        (2, mk.CUBE, "markers", 0),
    ]
    metadata = (tmp_path / "rec" / "metadata.yaml").read_text()
    assert "version: 9" in metadata and "storage_identifier: mcap" in metadata


def test_one_robot_reads_back_with_mcap(tmp_path: Path) -> None:
    states, arm = record_one(tmp_path / "rec")
    with open(tmp_path / "rec" / "rec.mcap", "rb") as file:
        reader = make_reader(file, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert summary is not None
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        for channel in summary.channels.values():
            qos = channel.metadata["offered_qos_profiles"]
            assert ("transient_local" in qos) == (channel.topic in LATCHED), channel.topic
        decoded = list(reader.iter_decoded_messages(topics=["/joint_states"]))
    assert len(decoded) == FRAMES
    for (t, q), (_, _, message, js) in zip(states, decoded):
        assert message.log_time == m.nanoseconds(t)
        assert list(js.name) == list(arm.tree.names)
        assert list(js.position)[: len(q)] == pytest.approx(q, abs=1e-9)


def test_a_cell_namespaces_topics_and_prefixes_frames(tmp_path: Path) -> None:
    left, right = bundled("motoman_sia20d"), bundled("fanuc_lrmate200id")
    with BagWriter(tmp_path / "cell") as writer:
        arms = {"left": BagRobot(writer, left, "left"), "right": BagRobot(writer, right, "right")}
        arms["left"].start(0.0, ((0.0, 0.5, 0.0), (0.0, 0.0, 0.0, 1.0)))
        arms["right"].start(0.0, ((0.0, -0.5, 0.0), (0.0, 0.0, 1.0, 0.0)))
        for i in range(10):
            arms["left"].frame(i * 0.01, left.home)
            arms["right"].frame(i * 0.01, right.home)
    _, by_topic = read_all(tmp_path / "cell")
    assert {
        "/left/joint_states",
        "/right/joint_states",
        "/left/robot_description",
        "/right/robot_description",
    } <= set(by_topic)
    assert by_topic["/right/robot_description"][0][1].data == right.source.xml
    # /tf_static collects: its last message holds both robots' fixed joints and placements.
    last = by_topic["/tf_static"][-1][1].transforms
    pairs = {(x.header.frame_id, x.child_frame_id) for x in last}
    assert {
        ("world", "left/base_link"),
        ("world", "right/base_link"),
        ("left/link_t", "left/tool0"),
    } <= pairs
    frames = {x.child_frame_id for _, tf in by_topic["/tf"] for x in tf.transforms}
    fingers = {f"right/gripper_finger_{side}" for side in ("left", "right")}  # its gripper's
    assert (
        frames
        == {
            f"left/{n}"
            for n in ("link_s", "link_l", "link_e", "link_u", "link_r", "link_b", "link_t")
        }
        | {f"right/link_{k}" for k in range(1, 7)}
        | fingers
    )


def test_an_empty_bag_is_still_a_bag(tmp_path: Path) -> None:
    BagWriter(tmp_path / "empty").close()
    with AnyReader([tmp_path / "empty"]) as reader:
        assert reader.message_count == 0 and reader.topics == {}
    with open(tmp_path / "empty" / "empty.mcap", "rb") as file:
        assert list(make_reader(file).iter_messages()) == []


def test_misuse(tmp_path: Path) -> None:
    with BagWriter(tmp_path / "rec") as writer:
        writer.text("/c2rviz/commands", 0.0, "home")
        with pytest.raises(MessageError, match="carries std_msgs/msg/String"):
            writer.write("/c2rviz/commands", m.JOINT_STATE, 0.0, m.joint_state(0.0, [], []))
        with pytest.raises(MessageError, match="negative"):
            writer.text("/c2rviz/commands", -1.0, "home")
        with pytest.raises(MessageError, match="unknown message type"):
            writer.write("/x", "my_msgs/msg/Thing", 0.0, {})
        with pytest.raises(MessageError, match="lacks field 'data'"):
            writer.write("/y", m.STRING, 0.0, {"text": "x"})
    with pytest.raises(BagError, match="exists already"):
        BagWriter(tmp_path / "rec")
    # A bag closed twice, or written after its close, stays as it was.
    writer.close()
    writer.text("/c2rviz/commands", 1.0, "late")
    with AnyReader([tmp_path / "rec"]) as reader:
        assert reader.message_count == 1
        assert list(reader.topics) == ["/c2rviz/commands"]  # nothing refused made a topic


def test_tf_static_repeats_every_static_transform(tmp_path: Path) -> None:
    with BagWriter(tmp_path / "rec") as writer:
        writer.tf_static(0.0, [m.transform(0.0, "world", "a", (1, 0, 0), (0, 0, 0, 1))])
        writer.tf_static(0.5, [m.transform(0.5, "world", "b", (0, 1, 0), (0, 0, 0, 1))])
        writer.tf_static(0.7, [m.transform(0.7, "world", "a", (2, 0, 0), (0, 0, 0, 1))])  # moved
    _, by_topic = read_all(tmp_path / "rec")
    contents = [
        sorted((x.child_frame_id, x.transform.translation.x) for x in message.transforms)
        for _, message in by_topic["/tf_static"]
    ]
    assert contents == [[("a", 1.0)], [("a", 1.0), ("b", 0.0)], [("a", 2.0), ("b", 0.0)]]
