"""A cell through one rosbridge endpoint: every robot under its namespace, one TF tree.

``left`` (motoman_sia20d) stands at the cell's origin, ``right`` (fanuc_lrmate200id)
1.2 m along x turned half a turn. Each robot's topics, frames and command service
live under its name; ``/tf`` and ``/tf_static`` are global and hang both robots
from the cell's ``world`` frame.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pinocchio as pin
import pytest
import roslibpy
from roslibpy.ros import set_rosapi_timeout
from support import load_robot
from world_support import (
    WAIT_S,
    WorldServer,
    ask,
    command_service,
    in_root,
    listen,
    tf_tree,
    until,
)

from c2rviz.robot.frames import pose_se3

RIGHT_ORIGIN = pose_se3((1.2, 0.0, 0.0, 0.0, 0.0, math.pi))
Q_LEFT = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
Q_RIGHT = [-0.3, 0.2, -0.1, 0.4, 0.5, 0.6]


@pytest.fixture
def cell() -> Iterator[WorldServer]:
    server = WorldServer(
        {"left": load_robot("motoman_sia20d"), "right": load_robot("fanuc_lrmate200id")},
        cell=True,
        origins={"right": RIGHT_ORIGIN},
    )
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture
def ros(cell: WorldServer) -> Iterator[roslibpy.Ros]:
    set_rosapi_timeout(WAIT_S)
    client = roslibpy.Ros("127.0.0.1", cell.port, transport="asyncio")
    client.run(timeout=WAIT_S)
    try:
        yield client
    finally:
        client.close()


def test_every_robot_under_its_namespace(cell: WorldServer, ros: roslibpy.Ros) -> None:
    topics = ros.get_topics()
    for robot in ("left", "right"):
        for name in ("joint_states", "c2rviz/command", "joint_trajectory", "robot_description"):
            assert f"/{robot}/{name}" in topics
    assert "/tf" in topics and "/tf_static" in topics and "/joint_states" not in topics
    assert set(ros.get_services()) >= {"/left/c2rviz/command", "/right/c2rviz/command"}
    assert ros.get_param("right/robot_description") == load_robot("fanuc_lrmate200id").source.xml
    assert ros.get_param("robot_description") == load_robot("motoman_sia20d").source.xml


def test_each_command_service_drives_its_robot(cell: WorldServer, ros: roslibpy.Ros) -> None:
    left = listen(ros, "/left/joint_states", "sensor_msgs/JointState")
    right = listen(ros, "/right/joint_states", "sensor_msgs/JointState")
    left.get(timeout=WAIT_S), right.get(timeout=WAIT_S)  # where they are now
    answer = ask(command_service(ros, "/right/c2rviz/command"), f"joints {_csv(Q_RIGHT)}")
    assert answer == {"reply": "ok", "ok": True}
    # The fanuc's /joint_states name its gripper's fingers too, after its arm's 6 joints.
    assert until(right, lambda m: m["position"][:6] != [0.0] * 6)["position"][:6] == Q_RIGHT
    assert ask(command_service(ros, "/left/c2rviz/command"), f"joints {_csv(Q_LEFT)}")["ok"]
    assert until(left, lambda m: m["position"] != [0.0] * 7)["position"] == Q_LEFT
    assert right.empty()  # the right arm did not move again
    assert cell.q("right") == tuple(Q_RIGHT)


def test_one_tf_tree_from_the_cells_world(cell: WorldServer, ros: roslibpy.Ros) -> None:
    static = listen(ros, "/tf_static", "tf2_msgs/msg/TFMessage").get(timeout=WAIT_S)
    moving = listen(ros, "/tf", "tf2_msgs/msg/TFMessage")
    topic = roslibpy.Topic(ros, "/right/joint_command", "sensor_msgs/msg/JointState")
    names = list(load_robot("fanuc_lrmate200id").joint_names)
    topic.publish(roslibpy.Message({"name": names, "position": Q_RIGHT}))
    robot = load_robot("fanuc_lrmate200id")
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(Q_RIGHT))
    wanted = RIGHT_ORIGIN * data.oMf[robot.model.getFrameId("link_6", pin.BODY)]

    def right_placed(msg: dict[str, Any]) -> bool:
        root, placement = in_root(tf_tree(static, msg), "right/link_6")
        return root == "world" and placement.isApprox(wanted, 1e-9)

    msg = until(moving, right_placed)
    children = {t["child_frame_id"] for t in msg["transforms"]}
    assert "left/link_t" in children  # every robot in each message
    assert all(c.startswith(("left/", "right/")) for c in children)


def test_events_and_markers_stay_in_their_namespace(cell: WorldServer, ros: roslibpy.Ros) -> None:
    left = listen(ros, "/left/c2rviz/events", "std_msgs/String")
    right = listen(ros, "/right/c2rviz/events", "std_msgs/String")
    markers = listen(ros, "/left/visualization_marker_array", "visualization_msgs/MarkerArray")
    markers.get(timeout=WAIT_S)
    assert ask(command_service(ros, "/left/c2rviz/command"), "mark 0.5,0,0.5,0,0,0")["ok"]
    assert left.get(timeout=WAIT_S)["data"].startswith("marker 0.5,0,0.5,0,0,0")
    added = until(markers, lambda m: bool(m["markers"]))["markers"][0]
    assert (added["header"]["frame_id"], added["ns"]) == ("world", "left/markers")
    assert ask(command_service(ros, "/right/c2rviz/command"), "clear")["ok"]
    assert right.get(timeout=WAIT_S)["data"] == "clear"
    assert ask(command_service(ros, "/left/c2rviz/command"), "mark 0.4,0,0.5,0,0,0")["ok"]
    assert left.get(timeout=WAIT_S)["data"].startswith("marker 0.4")  # no clear in between


def _csv(values: list[float]) -> str:
    return ",".join(map(str, values))
