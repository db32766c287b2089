"""roslibpy 2.1, the ROS community's Python client, against the rosbridge server.

roslibpy runs on its asyncio transport (``transport="asyncio"``): Autobahn on an
asyncio loop in roslibpy's own thread, one per process, which runs cleanly with
``filterwarnings = error``. Its twisted transport would bind txaio to Twisted
for the whole process; the two cannot be mixed, so every roslibpy test here
uses asyncio. roslibpy's calls block, so these are plain functions.
"""

from __future__ import annotations

import queue
from collections.abc import Iterator
from typing import Any

import pytest
import roslibpy
from rosbridge_support import WAIT_S, CounterBridge, ServerThread
from roslibpy.core import ServiceException
from roslibpy.ros import set_rosapi_timeout

from c2rviz.transports.rosbridge import COMMAND_SERVICE_TYPE, JointPositions
from c2rviz.transports.rosbridge.rosapi import ROSAPI_SERVICES


@pytest.fixture
def ros(rosbridge: ServerThread) -> Iterator[roslibpy.Ros]:
    set_rosapi_timeout(WAIT_S)
    client = roslibpy.Ros("127.0.0.1", rosbridge.port, transport="asyncio")
    client.run(timeout=WAIT_S)
    try:
        yield client
    finally:
        client.close()


def test_subscribe_and_receive_the_counter(rosbridge: ServerThread, ros: roslibpy.Ros) -> None:
    received: queue.Queue[dict[str, Any]] = queue.Queue()
    topic = roslibpy.Topic(ros, "/counter", "std_msgs/String")
    topic.subscribe(received.put)
    assert rosbridge.bridge.subscribed.get(timeout=WAIT_S) == "/counter"
    rosbridge.call(rosbridge.bridge.tick)
    assert received.get(timeout=WAIT_S) == {"data": "1"}
    rosbridge.call(rosbridge.bridge.tick)
    assert received.get(timeout=WAIT_S) == {"data": "2"}
    topic.unsubscribe()
    assert rosbridge.bridge.unsubscribed.get(timeout=WAIT_S) == "/counter"


def test_a_late_subscriber_gets_the_latched_message(ros: roslibpy.Ros) -> None:
    received: queue.Queue[dict[str, Any]] = queue.Queue()
    roslibpy.Topic(ros, "/latched", "std_msgs/msg/String").subscribe(received.put)
    assert received.get(timeout=WAIT_S) == {"data": "latched hello"}


def test_publish_arrives_at_the_bridge(rosbridge: ServerThread, ros: roslibpy.Ros) -> None:
    roslibpy.Topic(ros, "/inbox", "std_msgs/String").publish(roslibpy.Message({"data": "hello"}))
    source, topic, text = rosbridge.bridge.published.get(timeout=WAIT_S)
    assert (topic, text) == ("/inbox", "hello")
    assert source.startswith("rosbridge 127.0.0.1:")


def test_a_joint_state_arrives_checked_and_bad_ones_do_not(
    rosbridge: ServerThread, ros: roslibpy.Ros
) -> None:
    topic = roslibpy.Topic(ros, "/joint_command", "sensor_msgs/msg/JointState")
    topic.publish(roslibpy.Message({"name": ["j1", "j2"], "position": [0.5, float("nan")]}))
    topic.publish(roslibpy.Message({"name": ["j1"], "position": [0.1], "effort": [1.0, 2.0]}))
    topic.publish(roslibpy.Message({"name": ["j1", "j2"], "position": [0.5, -0.25]}))
    _, _, command = rosbridge.bridge.published.get(timeout=WAIT_S)
    assert command == JointPositions(("j1", "j2"), (0.5, -0.25))
    assert rosbridge.server.stats["errors"] == 2  # each answered with a status


def test_call_service_comes_back_to_its_caller(ros: roslibpy.Ros) -> None:
    service = roslibpy.Service(ros, "/c2rviz/command", COMMAND_SERVICE_TYPE)
    answers: queue.Queue[dict[str, Any]] = queue.Queue()
    service.call(roslibpy.ServiceRequest({"command": "second"}), answers.put)
    first = service.call(roslibpy.ServiceRequest({"command": "first"}), timeout=WAIT_S)
    assert first == {"reply": "did first", "ok": True}
    assert answers.get(timeout=WAIT_S) == {"reply": "did second", "ok": True}


def test_a_refused_service_call_raises(ros: roslibpy.Ros) -> None:
    service = roslibpy.Service(ros, "/c2rviz/command", COMMAND_SERVICE_TYPE)
    with pytest.raises(ServiceException, match="fail: refused on purpose"):
        service.call(roslibpy.ServiceRequest({"command": "fail"}), timeout=WAIT_S)


def test_a_slow_service_holds_its_connection_only(
    rosbridge: ServerThread, ros: roslibpy.Ros
) -> None:
    rosbridge.call(rosbridge.bridge.release.clear)
    held: queue.Queue[dict[str, Any]] = queue.Queue()
    service = roslibpy.Service(ros, "/c2rviz/command", COMMAND_SERVICE_TYPE)
    service.call(roslibpy.ServiceRequest({"command": "hold"}), held.put)
    assert rosbridge.bridge.calls.get(timeout=WAIT_S) == "hold"
    other = roslibpy.Ros("127.0.0.1", rosbridge.port, transport="asyncio")
    other.run(timeout=WAIT_S)
    try:
        assert other.get_topics() == [t for t, _ in CounterBridge.TOPICS]
    finally:
        other.close()
    assert held.empty()
    rosbridge.call(rosbridge.bridge.release.set)
    assert held.get(timeout=WAIT_S) == {"reply": "did hold", "ok": True}


def test_the_rosapi_helpers(ros: roslibpy.Ros) -> None:
    assert ros.get_topics() == ["/counter", "/latched", "/inbox", "/joint_command"]
    assert ros.get_topic_type("/joint_command") == "sensor_msgs/msg/JointState"
    assert ros.get_topic_type("latched") == "std_msgs/msg/String"
    assert ros.get_topic_type("/nope") == ""
    assert ros.get_services() == ["/c2rviz/command", *ROSAPI_SERVICES]
    assert ros.get_service_type("/c2rviz/command") == COMMAND_SERVICE_TYPE
    assert ros.get_topics_for_type("std_msgs/String") == ["/counter", "/latched", "/inbox"]
    assert ros.get_nodes() == ["/c2rviz"]
    assert ros.get_param("robot_description") == "<robot name='counter'/>"
    assert roslibpy.Param(ros, "/c2rviz:robot_description").get(timeout=WAIT_S).startswith("<robot")
    assert ros.get_params() == ["/c2rviz:robot_description"]
