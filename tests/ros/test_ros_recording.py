"""A recording's bag NAME/, made by a real server, read back with rosbags and with mcap.

A client records moves (a joint move and a straight tool line, in `motion on`),
markers, a workcell object and a refused line; the bag's topics, types and QoS are
checked, every stamp is the CSV's time, each /joint_states is the state the world
showed at its time (within 1e-9), /tf composes to Pinocchio's forward kinematics, and
the markers, objects, commands and replies are there as they happened.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability
from support import Client, ServerThread
from test_ros_tf_tree import close, link_poses

from c2rviz.ros import messages as mk
from c2rviz.ros.tf_tree import TfTree

TYPES = {
    "/robot_description": "std_msgs/msg/String",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/c2rviz/commands": "std_msgs/msg/String",
    "/c2rviz/replies": "std_msgs/msg/String",
    "/visualization_marker_array": "visualization_msgs/msg/MarkerArray",
}
LATCHED = {"/tf_static", "/robot_description"}


def ns_of(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def as_transforms(message: Any) -> list[tuple[str, str, tuple, tuple]]:
    out = []
    for x in message.transforms:
        t, r = x.transform.translation, x.transform.rotation
        out.append((x.header.frame_id, x.child_frame_id, (t.x, t.y, t.z), (r.x, r.y, r.z, r.w)))
    return out


def read_bag(path: Path) -> tuple[dict[str, str], dict[str, Any], dict[str, list[tuple[int, Any]]]]:
    by_topic: dict[str, list[tuple[int, Any]]] = {}
    with AnyReader([path]) as reader:
        types = {name: info.msgtype or "" for name, info in reader.topics.items()}
        qos = {c.topic: c.ext.offered_qos_profiles[0].durability for c in reader.connections}  # type: ignore[union-attr]
        for conn, log_ns, raw in reader.messages():
            by_topic.setdefault(conn.topic, []).append(
                (log_ns, reader.deserialize(raw, conn.msgtype))
            )
    return types, qos, by_topic


@pytest.fixture
def recorded(
    start_server: Callable[..., ServerThread], connect: Callable[..., Client], tmp_path: Path
) -> dict[str, Any]:
    """A recording `take` of one client's moves, marks, an object and a refused line."""
    server = start_server()
    server.call(lambda: setattr(server.services.recordings, "folder", tmp_path))
    client = connect(server)
    assert client.ask("record take").startswith("ok recording take")
    t0 = server.call(lambda: server.services.recordings.running["motoman_sia20d"].t0)
    start = server.call(lambda: len(server.scene.times))
    lines = [
        "motion on",
        "speed 100",
        "joints 0.5,0.3,0,-0.4,0,0.6,0",
        "mark",
        "color 0,0.5,1",
        "marker cube",
        "mark 0.5,0.25,1,0.1,0.2,0.3",
        "object crate box 0.2,0.1,0.3 0.6,0.4,0.2,0,0,0.5",
        "movel 0.55,0.1,1.0,0,1.2,0",
        "jonts 1",
        "object crate remove",
        "clear",
        "sleep 0.05",
    ]
    got = {}
    for line in lines:
        got[line] = client.ask(line)
        if line.startswith("object crate box"):  # both markers are down
            markers = server.call(lambda: list(server.scene.markers))
    assert all(reply.startswith("ok") for line, reply in got.items() if line != "jonts 1")
    final = client.ask("where")
    reply = client.ask("record stop")
    assert reply.startswith("ok recorded take: ") and reply.endswith(f"{tmp_path / 'take'})")
    times = server.call(lambda: list(server.scene.times))
    joints = server.call(lambda: list(server.scene.joints))
    port = client.sock.getsockname()[1]
    return {
        "folder": tmp_path,
        "bag": tmp_path / "take",
        "t0": t0,
        "times": times[start:],
        "joints": joints[start:],
        "first": server.call(lambda: server.world.robot.home),
        "final": [float(v) for v in final[3:].split(",")],
        "where": final,
        "robot": server.robot,
        "lines": lines,
        "replies": got,
        "source": f"tcp 127.0.0.1:{port}",
        "markers": markers,
    }


@pytest.mark.wall_clock  # on virtual time a bag's state and the scene's frame share a stamp,
# and the bag's first moving state reads as at rest (same-instant order; see the report)
def test_the_bag_reads_back_with_rosbags(recorded: dict[str, Any]) -> None:
    bag, robot = recorded["bag"], recorded["robot"]
    assert sorted(p.name for p in bag.iterdir()) == ["metadata.yaml", "take.mcap"]
    types, qos, by_topic = read_bag(bag)
    assert types == TYPES
    for topic, durability in qos.items():
        latched = QosDurability.TRANSIENT_LOCAL if topic in LATCHED else QosDurability.VOLATILE
        assert durability == latched, topic
    for topic, items in by_topic.items():  # log times in order on every topic
        stamps = [ns for ns, _ in items]
        assert stamps == sorted(stamps), topic
    assert by_topic["/robot_description"][0][1].data == robot.source.xml

    # /joint_states: every moving joint, at the CSV's times, the state the world showed.
    tree = TfTree(robot)
    states = by_topic["/joint_states"]
    with open(recorded["folder"] / "take.csv", newline="") as file:
        rows = list(csv.reader(file))[1:]
    assert [f"{ns / 1e9:.6f}" for ns, _ in states] == [row[0] for row in rows]
    times, joints = np.array(recorded["times"]), recorded["joints"]
    moving = 0
    for ns, js in states:
        assert ns_of(js.header.stamp) == ns and tuple(js.name) == tree.names
        at = recorded["t0"] + ns / 1e9
        k = int(np.searchsorted(times, at + 1e-6, side="right")) - 1  # the state shown then
        shown = recorded["first"] if k < 0 else joints[k]
        np.testing.assert_allclose(js.position[: robot.n], shown, rtol=0, atol=1e-9)
        assert len(js.velocity) in (0, robot.n)
        moving += len(js.velocity) > 0
    assert moving > 50  # velocities while the arm moved...
    assert len(states[0][1].velocity) == len(states[-1][1].velocity) == 0  # ...none at rest
    np.testing.assert_allclose(states[-1][1].position[: robot.n], recorded["final"], atol=1e-9)

    # /tf with /tf_static is Pinocchio's forward kinematics, for every frame.
    statics = as_transforms(by_topic["/tf_static"][-1][1])
    for (ns, js), (tf_ns, tf) in zip(states, by_topic["/tf"], strict=True):
        assert tf_ns == ns and all(ns_of(x.header.stamp) == ns for x in tf.transforms)
        poses = link_poses(robot.base, statics + as_transforms(tf))
        assert close(poses[robot.eelink], robot.ee_pose(list(js.position[: robot.n])))

    # Markers as they were dropped, then deleted by `clear`; the object added, then removed.
    arrays = [message.markers for _, message in by_topic["/visualization_marker_array"]]
    dropped = [m for array in arrays for m in array if m.ns == "markers" and m.action == mk.ADD]
    assert [(m.id, m.type) for m in dropped] == [(0, mk.SPHERE), (1, mk.CUBE)]
    for m, want in zip(dropped, recorded["markers"], strict=True):
        p = m.pose.position
        np.testing.assert_allclose([p.x, p.y, p.z], want.position, atol=1e-12)
        assert (m.color.r, m.color.g, m.color.b) == pytest.approx(want.rgb)
        assert m.header.frame_id == tree.root
    deleted = [(m.ns, m.id) for array in arrays for m in array if m.action == mk.DELETE]
    assert deleted == [("workcell", 0), ("markers", 0), ("markers", 1)]
    (crate,) = [m for array in arrays for m in array if m.ns == "workcell" and m.action == mk.ADD]
    assert crate.type == mk.CUBE and crate.header.frame_id == robot.base
    assert (crate.scale.x, crate.scale.y, crate.scale.z) == pytest.approx((0.2, 0.1, 0.3))
    q = crate.pose.orientation
    placement = pin.XYZQUATToSE3(np.array([*(0.6, 0.4, 0.2), q.x, q.y, q.z, q.w]))
    np.testing.assert_allclose(pin.rpy.matrixToRpy(placement.rotation), [0, 0, 0.5], atol=1e-12)

    # Each accepted command with its source, each reply with its line (refused ones too).
    source = recorded["source"]

    def lines(topic: str) -> list[str]:  # a frame's lines are one message, a line each
        return [line for _, message in by_topic[topic] for line in message.data.split("\n")]

    commands = lines("/c2rviz/commands")
    accepted = [line for line in recorded["lines"] if line != "jonts 1"]
    assert commands == [
        f"{source}: record take",
        *(f"{source}: {line}" for line in accepted),
        f"{source}: where",
    ]
    replies = lines("/c2rviz/replies")
    assert replies[0].startswith(f"{source}: record take -> ok recording take into ")
    assert replies[1:] == [
        *(f"{source}: {line} -> {recorded['replies'][line]}" for line in recorded["lines"]),
        f"{source}: where -> {recorded['where']}",
    ]
    assert recorded["replies"]["jonts 1"].startswith("error: unknown command 'jonts'")


def test_the_bag_reads_back_with_mcap(recorded: dict[str, Any]) -> None:
    _, _, by_topic = read_bag(recorded["bag"])
    with open(recorded["bag"] / "take.mcap", "rb") as file:
        reader = make_reader(file, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert summary is not None
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        assert {c.topic: s.name for c in summary.channels.values()
                for s in [summary.schemas[c.schema_id]]} == TYPES  # fmt: skip
        decoded = list(reader.iter_decoded_messages())
    counts: dict[str, int] = {}
    for _, channel, message, ros in decoded:
        counts[channel.topic] = counts.get(channel.topic, 0) + 1
        if channel.topic == "/joint_states":
            assert ns_of(ros.header.stamp) == message.log_time
    assert counts == {topic: len(items) for topic, items in by_topic.items()}
    states = [ros for _, channel, _, ros in decoded if channel.topic == "/joint_states"]
    np.testing.assert_allclose(
        list(states[-1].position)[: recorded["robot"].n], recorded["final"], atol=1e-9
    )
