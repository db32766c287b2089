"""A camera on rosbridge: its PoseArray topic (in the camera's frame), listed by rosapi
with its type, and the camera's and its seen parts' frames on ``/tf``."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import roslibpy
from roslibpy.ros import set_rosapi_timeout
from support import load_robot
from world_support import WAIT_S, WorldServer, ask, command_service, listen, until

from c2rviz.transports.rosbridge.rosapi import full_text


@pytest.fixture
def ros() -> Iterator[roslibpy.Ros]:
    server = WorldServer({"fanuc_lrmate200id": load_robot("fanuc_lrmate200id")})
    set_rosapi_timeout(WAIT_S)
    client = roslibpy.Ros("127.0.0.1", server.port, transport="asyncio")
    try:
        client.run(timeout=WAIT_S)
        yield client
    finally:
        client.close()
        server.stop()


def _frame(msg: dict[str, Any], child: str) -> dict[str, Any] | None:
    return next((t for t in msg["transforms"] if t["child_frame_id"] == child), None)


def test_a_camera_publishes_what_it_sees_and_its_frames(ros: roslibpy.Ros) -> None:
    service = command_service(ros)
    for line in (
        "part p1 box 0.03,0.03,0.03 1,0,0.015,0,0,0 type=battery",
        "camera top 1,0,1.5,0,1.5707963267948966,0",
        "camera top rate 20",
    ):
        assert ask(service, line)["ok"], line
    topics = dict(zip(*_topics_and_types(ros)))
    assert topics["/c2rviz/cameras/top"] == "geometry_msgs/msg/PoseArray"
    tf = listen(ros, "/tf", "tf2_msgs/msg/TFMessage")
    seen = listen(ros, "/c2rviz/cameras/top", "geometry_msgs/msg/PoseArray")
    msg = until(seen, lambda m: len(m["poses"]) == 1)
    assert msg["header"]["frame_id"] == "cameras/top"
    assert msg["poses"][0]["position"]["x"] == pytest.approx(1.485)
    frames = until(tf, lambda m: _frame(m, "cameras/top/p1") is not None)
    camera = _frame(frames, "cameras/top")
    assert camera is not None and camera["header"]["frame_id"] == "base_link"
    assert camera["transform"]["translation"]["z"] == pytest.approx(1.5)
    part = _frame(frames, "cameras/top/p1")
    assert part is not None and part["header"]["frame_id"] == "cameras/top"
    assert ask(service, "object wall box 0.4,0.4,0.02 1,0,0.5,0,0,0")["ok"]
    assert until(seen, lambda m: m["poses"] == [])["header"]["frame_id"] == "cameras/top"


def _topics_and_types(ros: roslibpy.Ros) -> tuple[list[str], list[str]]:
    service = roslibpy.Service(ros, "/rosapi/topics", "rosapi/Topics")
    result = service.call(roslibpy.ServiceRequest(), timeout=WAIT_S)
    return result["topics"], result["types"]


def test_the_pose_array_definition_is_rosbags_own() -> None:
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    assert "geometry_msgs/msg/PoseArray" in store.fielddefs
    assert full_text("geometry_msgs/msg/PoseArray").startswith(
        "std_msgs/Header header\ngeometry_msgs/Pose[] poses\n"
    )
