"""roslibpy against a real c2rviz server: the robot's topics, commands, services and trajectories.

The server is the world, its services, the text port and the rosbridge door
(``world_support.WorldServer``); roslibpy runs on its asyncio transport. A
command from rosbridge is a session's command like any other: checked, noted
among the world's commands with its source, and shown on the robot's topics.
"""

from __future__ import annotations

import math
import queue
import time
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import roslibpy
from roslibpy.core import ServiceException
from support import load_robot
from world_support import (
    WAIT_S,
    WorldServer,
    ask,
    command_service,
    in_root,
    listen,
    seconds,
    text_client,
    tf_tree,
    until,
)

Q1 = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]


def test_joint_states_show_a_joints_command(world_server: WorldServer, ros_world: roslibpy.Ros):
    states = listen(ros_world, "/joint_states", "sensor_msgs/JointState")
    robot = load_robot("motoman_sia20d")
    greeting = states.get(timeout=WAIT_S)  # where the arm is, at once
    assert greeting["name"] == list(robot.joint_names)
    assert greeting["position"] == list(robot.home)
    client = text_client(world_server)
    try:
        assert client.ask("joints " + ",".join(map(str, Q1))) == "ok"
    finally:
        client.close()
    msg = until(states, lambda m: m["position"] != list(robot.home))
    assert msg["position"] == Q1
    assert abs(seconds(msg["header"]["stamp"]) - time.monotonic()) < WAIT_S  # the world's clock


def test_a_command_published_is_answered_on_the_reply_topic(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    replies = listen(ros_world, "/c2rviz/reply", "std_msgs/String")
    command = roslibpy.Topic(ros_world, "/c2rviz/command", "std_msgs/msg/String")
    ask(command_service(ros_world), "help")  # the subscription is in place once this returns
    command.publish(roslibpy.Message({"data": "joints " + ",".join(map(str, Q1))}))
    assert replies.get(timeout=WAIT_S) == {"data": "ok"}
    command.publish(roslibpy.Message({"data": "where"}))
    assert replies.get(timeout=WAIT_S) == {"data": "ok " + ",".join(map(str, Q1))}
    command.publish(roslibpy.Message({"data": "joints 9,9,9,9,9,9,9"}))
    assert replies.get(timeout=WAIT_S)["data"].startswith("error: joint_s (index 0) = 9 rad")
    assert world_server.q() == tuple(Q1)
    notes = world_server.notes_of("joints")
    assert [n.accepted for n in notes] == [True, False]
    assert all(n.source.startswith("rosbridge 127.0.0.1:") for n in notes)  # "last commands"


def test_the_command_service(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    service = command_service(ros_world)
    assert ask(service, "degrees") == {"reply": "ok", "ok": True}
    assert ask(service, "joints 10,0,0,0,0,0,0") == {"reply": "ok", "ok": True}  # its units
    assert world_server.q()[0] == pytest.approx(math.radians(10), abs=1e-12)
    answer = ask(service, "fly away")
    assert answer["ok"] is False and answer["reply"].startswith("error: unknown command 'fly'")
    assert ask(service, "") == {"reply": "", "ok": True}  # a blank line has no reply
    with pytest.raises(ServiceException, match="command is missing"):
        service.call(roslibpy.ServiceRequest({}), timeout=WAIT_S)


def test_a_service_call_waits_for_its_reply(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    service = command_service(ros_world)
    now = lambda: world_server.call(world_server.world.clock.now)  # noqa: E731
    assert ask(service, "motion on") == {"reply": "ok", "ok": True}
    started = now()
    assert ask(service, "joints 0.5,0,0,0,0,0,0") == {"reply": "ok", "ok": True}  # on arrival
    took = now() - started
    assert world_server.q()[0] == 0.5
    # Judged on the world's clock against the move itself, not a figure of the wall: the
    # way back is as long, and the reply above waited at least that long.
    assert ask(service, "motion follow") == {"reply": "ok", "ok": True}
    assert ask(service, "joints 0,0,0,0,0,0,0") == {"reply": "ok", "ok": True}  # at once
    status = ask(service, "status")["reply"]
    assert status.startswith("ok moving "), status
    assert took >= float(status.split()[-1]) > 0


def test_discovery(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    topics = ros_world.get_topics()
    for name in (
        "/joint_states",
        "/tf",
        "/tf_static",
        "/robot_description",
        "/c2rviz/events",
        "/visualization_marker_array",
        "/c2rviz/command",
        "/c2rviz/reply",
        "/joint_command",
        "/joint_trajectory",
    ):
        assert name in topics
    assert ros_world.get_topic_type("/joint_trajectory") == "trajectory_msgs/msg/JointTrajectory"
    assert "/c2rviz/command" in ros_world.get_services()
    assert ros_world.get_nodes() == ["/c2rviz"]
    urdf = load_robot("motoman_sia20d").source.xml
    assert ros_world.get_param("robot_description") == urdf
    assert world_server.call(lambda: world_server.services.client_count) == 1  # the page says so


def test_latched_topics_reach_a_late_subscriber(ros_world: roslibpy.Ros) -> None:
    description = listen(ros_world, "/robot_description", "std_msgs/String")
    assert description.get(timeout=WAIT_S)["data"] == load_robot("motoman_sia20d").source.xml
    static = listen(ros_world, "/tf_static", "tf2_msgs/msg/TFMessage")
    assert isinstance(static.get(timeout=WAIT_S)["transforms"], list)


def test_tf_is_the_robot_as_pinocchio_places_it(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    static = listen(ros_world, "/tf_static", "tf2_msgs/msg/TFMessage").get(timeout=WAIT_S)
    moving = listen(ros_world, "/tf", "tf2_msgs/msg/TFMessage")
    assert ask(command_service(ros_world), "joints " + ",".join(map(str, Q1)))["ok"]
    robot = load_robot("motoman_sia20d")
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(Q1))
    wanted = data.oMf[robot.model.getFrameId("link_t", pin.BODY)]

    def at_q1(msg: dict[str, Any]) -> bool:
        root, placement = in_root(tf_tree(static, msg), "link_t")
        return root == "base_link" and placement.isApprox(wanted, 1e-9)

    until(moving, at_q1)


def test_joint_command_moves_the_named_joints(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    states = listen(ros_world, "/joint_states", "sensor_msgs/JointState")
    states.get(timeout=WAIT_S)
    topic = roslibpy.Topic(ros_world, "/joint_command", "sensor_msgs/msg/JointState")
    topic.publish(roslibpy.Message({"name": ["joint_b", "joint_s"], "position": [0.25, -0.5]}))
    msg = until(states, lambda m: m["position"][0] != 0.0)
    assert msg["position"] == [-0.5, 0.0, 0.0, 0.0, 0.0, 0.25, 0.0]
    note = world_server.notes_of("/joint_command")[-1]
    assert (note.line, note.accepted) == ("/joint_command joint_b=0.25,joint_s=-0.5", True)


def test_a_trajectory_arrives_on_time(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    states = listen(ros_world, "/joint_states", "sensor_msgs/JointState")
    states.get(timeout=WAIT_S)
    points = [(1.0, [0.3, -0.1]), (1.75, [0.5, 0.05]), (2.5, [0.6, 0.1])]
    message = {
        "joint_names": ["joint_s", "joint_l"],
        "points": [
            {"positions": p, "time_from_start": {"sec": int(t), "nanosec": round(t % 1 * 1e9)}}
            for t, p in points
        ],
    }
    before = time.monotonic()  # the world's clock is this process's monotonic clock
    roslibpy.Topic(ros_world, "/joint_trajectory", "trajectory_msgs/JointTrajectory").publish(
        roslibpy.Message(message)
    )
    samples: list[tuple[float, list[float]]] = []
    while not samples or samples[-1][1][:2] != points[-1][1]:
        msg = states.get(timeout=WAIT_S)
        samples.append((seconds(msg["header"]["stamp"]), msg["position"]))
    start = world_server.notes_of("/joint_trajectory")[-1].t
    assert before <= start <= samples[0][0]
    stamps = np.array([s for s, _ in samples])
    assert np.all(np.diff(stamps) > 0)
    end = start + points[-1][0]  # moving until then, at the last point from then on
    assert samples[-2][0] < end <= samples[-1][0] + 1e-4
    positions = np.array([p[:2] for _, p in samples])
    for t, wanted in points:  # the arm passes each point at its time
        between = [np.interp(start + t, stamps, positions[:, j]) for j in range(2)]
        assert between == pytest.approx(wanted, abs=5e-3)
    assert all(p[2:] == [0.0] * 5 for _, p in samples)  # joints it does not name hold still


def test_events_and_markers(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    events = listen(ros_world, "/c2rviz/events", "std_msgs/String")
    markers = listen(ros_world, "/visualization_marker_array", "visualization_msgs/MarkerArray")
    snapshot = markers.get(timeout=WAIT_S)["markers"]
    assert [(m["ns"], m["action"]) for m in snapshot] == [("markers", 3), ("workcell", 3)]
    service = command_service(ros_world)
    assert ask(service, "mark 0.5,0.1,0.6,0,0,0")["ok"]
    assert events.get(timeout=WAIT_S)["data"] == "marker 0.5,0.1,0.6,0,0,0 sphere 1,0,0"
    added = until(markers, lambda m: bool(m["markers"]))["markers"]
    assert [(m["ns"], m["id"], m["action"], m["type"]) for m in added] == [("markers", 0, 0, 2)]
    position = added[0]["pose"]["position"]
    assert (position["x"], position["y"], position["z"]) == pytest.approx((0.5, 0.1, 0.6))
    assert added[0]["header"]["frame_id"] == "base_link"
    assert ask(service, "clear")["ok"]
    assert events.get(timeout=WAIT_S)["data"] == "clear"
    cleared = until(markers, lambda m: any(x["action"] == 3 for x in m["markers"]))
    assert [(m["ns"], m["action"]) for m in cleared["markers"]] == [("markers", 3)]
    assert ask(service, "motion on")["ok"] and ask(service, "joints 0.2,0,0,0,0,0,0")["ok"]
    assert until(events, lambda m: m["data"] == "arrived")


def test_quit_from_rosbridge_stops_the_program(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    assert ask(command_service(ros_world), "quit") == {"reply": "ok", "ok": True}
    assert world_server.quit.wait(WAIT_S)


def test_a_bad_message_is_answered_with_a_status(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    statuses: queue.Queue[dict[str, Any]] = queue.Queue()
    # roslibpy 2.1 reads no status frames (it logs each as unhandled): give it a handler.
    ros_world.factory.on_ready(lambda proto: proto._message_handlers.update(status=statuses.put))
    ask(command_service(ros_world), "help")
    topic = roslibpy.Topic(ros_world, "/joint_command", "sensor_msgs/msg/JointState")
    topic.publish(roslibpy.Message({"name": ["joint_s", "elbow"], "position": [0.5, 0.5]}))
    status = statuses.get(timeout=WAIT_S)
    assert status["level"] == "error"
    assert "'elbow' is not a joint of motoman_sia20d's chain" in status["msg"]
    assert world_server.q() == load_robot("motoman_sia20d").home  # nothing moved


def test_a_marker_flood_leaves_a_subscriber_with_the_newest_thousand(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    markers = listen(ros_world, "/visualization_marker_array", "visualization_msgs/MarkerArray")
    shown: dict[int, float] = {}  # id -> x, as RViz would hold them

    def apply(msg: dict[str, Any]) -> bool:
        for marker in msg["markers"]:
            if marker["ns"] != "markers":
                continue
            if marker["action"] == 3:
                shown.clear()
            elif marker["action"] == 2:
                del shown[marker["id"]]
            else:
                shown[marker["id"]] = marker["pose"]["position"]["x"]
        return max(shown, default=-1) == 1499

    client = text_client(world_server)
    try:
        client.send("".join(f"mark {k / 1000},0,0.5,0,0,0\n" for k in range(1500)))
        assert [client.read_line() for _ in range(1500)][-1] == "ok"
    finally:
        client.close()
    until(markers, apply)
    assert sorted(shown) == list(range(500, 1500))
    assert shown[1499] == pytest.approx(1.499)


def test_diagnostics_tell_the_faults(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    diagnostics = listen(ros_world, "/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
    greeting = diagnostics.get(timeout=WAIT_S)["status"]
    assert [(s["name"], s["level"], s["message"], s["values"]) for s in greeting] == [
        ("c2rviz/motoman_sia20d", 0, "ok", [])
    ]
    service = command_service(ros_world)
    assert ask(service, "fault estop")["ok"]
    stopped = until(diagnostics, lambda m: m["status"][0]["level"] == 2)["status"][0]
    assert stopped["message"].startswith("emergency stop since t=")
    assert stopped["hardware_id"] == "motoman_sia20d"
    assert [v["key"] for v in stopped["values"]] == ["estop"]
    reply = ask(service, "joints " + ",".join(map(str, Q1)))  # refused on this door too
    assert not reply["ok"] and reply["reply"].startswith("error: emergency stop since t=")
    assert ask(service, "fault clear estop")["ok"] and ask(service, "reset")["ok"]
    assert ask(service, "fault noise 0.01")["ok"]
    noisy = until(diagnostics, lambda m: m["status"][0]["level"] == 1)["status"][0]
    assert noisy["message"] == "faults: noise 0.01"
    assert ask(service, "fault clear")["ok"]
    assert (
        until(diagnostics, lambda m: m["status"][0]["level"] == 0)["status"][0]["message"] == "ok"
    )


def test_joint_states_carry_the_noise(world_server: WorldServer, ros_world: roslibpy.Ros):
    states = listen(ros_world, "/joint_states", "sensor_msgs/JointState")
    assert states.get(timeout=WAIT_S)["position"] == [0.0] * 7
    service = command_service(ros_world)
    assert ask(service, "fault noise 0.01")["ok"]
    assert ask(service, "joints " + ",".join(map(str, Q1)))["ok"]
    msg = until(states, lambda m: m["position"] != [0.0] * 7)
    assert msg["position"] != Q1
    assert msg["position"] == pytest.approx(Q1, abs=0.06)
    assert ask(service, "target")["reply"] == "ok " + ",".join(map(str, Q1))
