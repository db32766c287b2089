"""Issue 39's faults at the rosbridge door (5, 6, 7, 8, 9), each through a real server."""

from __future__ import annotations

import json
import queue
import re
import threading
import time
from typing import Any

import pytest
import roslibpy
from rosbridge_support import CounterBridge, ServerThread
from support import ROOT, load_robot
from websockets.sync.client import connect
from world_support import WAIT_S, WorldServer, ask, command_service

from c2rviz.transports.rosbridge import RosbridgePolicy
from c2rviz.transports.rosbridge.messages import MessageError, joint_positions, joint_trajectory
from c2rviz.transports.rosbridge.server import CLOSE_TIMEOUT_S

HUGE = 10**400  # 401 digits: JSON allows it, a float64 cannot hold it
POINT = {"positions": [0.0] * 7, "time_from_start": {"sec": 1, "nanosec": 0}}
NAMES = ["joint_s", "joint_l", "joint_e", "joint_u", "joint_r", "joint_b", "joint_t"]


def trajectory(**changed: Any) -> dict[str, Any]:
    return {"joint_names": NAMES, "points": [POINT | changed]}


@pytest.mark.parametrize(
    ("read", "msg", "field"),
    [
        (joint_positions, {"name": ["joint_s"], "position": [HUGE]}, "position[0]"),
        (
            joint_positions,
            {"name": ["joint_s"], "position": [0], "velocity": [-HUGE]},
            "velocity[0]",
        ),
        (
            joint_trajectory,
            trajectory(positions=[0, 0, HUGE, 0, 0, 0, 0]),
            "points[0].positions[2]",
        ),
        (joint_trajectory, trajectory(velocities=[HUGE] + [0] * 6), "points[0].velocities[0]"),
        (
            joint_trajectory,
            trajectory(accelerations=[0] * 6 + [HUGE]),
            "points[0].accelerations[6]",
        ),
    ],
    ids=["position", "state-velocity", "trajectory-position", "velocity", "acceleration"],
)
def test_a_huge_integer_is_refused_naming_its_field(read, msg: dict, field: str) -> None:
    """39.7: ``float(10**400)`` raised OverflowError ("internal error in c2rviz")."""
    with pytest.raises(MessageError, match="too large for a float64") as refused:
        read(msg)
    assert refused.value.field == field


def statuses_of(ros: roslibpy.Ros) -> queue.Queue[dict[str, Any]]:
    """The status frames roslibpy gets (roslibpy 2.1 has no handler of its own)."""
    statuses: queue.Queue[dict[str, Any]] = queue.Queue()
    ros.factory.on_ready(lambda proto: proto._message_handlers.update(status=statuses.put))
    return statuses


@pytest.mark.parametrize(
    ("topic", "kind", "msg", "field"),
    [
        ("/joint_command", "sensor_msgs/msg/JointState", {"name": ["joint_s"], "position": [HUGE]},
         "position[0]"),
        ("/joint_trajectory", "trajectory_msgs/msg/JointTrajectory",
         trajectory(velocities=[HUGE] + [0] * 6), "points[0].velocities[0]"),
    ],
    ids=["joint-command", "trajectory-velocity"],
)  # fmt: skip
def test_a_huge_integer_through_the_door_is_a_status_naming_the_field(
    world_server: WorldServer, ros_world: roslibpy.Ros, topic: str, kind: str, msg: dict, field: str
) -> None:
    statuses = statuses_of(ros_world)
    ask(command_service(ros_world), "help")
    roslibpy.Topic(ros_world, topic, kind).publish(roslibpy.Message(msg))
    status = statuses.get(timeout=WAIT_S)
    assert status["level"] == "error" and "internal error" not in status["msg"]
    assert f"{field} is an integer too large for a float64" in status["msg"], status["msg"]
    assert world_server.q() == load_robot("motoman_sia20d").home
    assert ask(command_service(ros_world), "where")["ok"]  # the connection goes on


def test_without_a_throttle_every_message_is_sent(
    rosbridge: ServerThread, bridge: CounterBridge
) -> None:
    """39.5: roslibpy's default (``throttle_rate`` 0, ``queue_length`` 0) kept one message
    and dropped the rest; rosbridge_suite applies ``queue_length`` only with a throttle."""
    with connect(rosbridge.url, open_timeout=WAIT_S) as client:
        subscribe = {"op": "subscribe", "id": "c", "topic": "/counter", "throttle_rate": 0}
        client.send(json.dumps(subscribe | {"queue_length": 0}))
        assert bridge.subscribed.get(timeout=WAIT_S) == "/counter"
        rosbridge.call(bridge.tick, 8)  # eight before the outbox can send one
        got = [json.loads(client.recv(timeout=WAIT_S))["msg"]["data"] for _ in range(8)]
        assert got == [str(n) for n in range(1, 9)]
        assert rosbridge.server.stats["thinned"] == 0


def test_roslibpy_gets_every_reply(world_server: WorldServer, ros_world: roslibpy.Ros) -> None:
    """39.5 as it was seen: eight commands published at once, four replies arrived."""
    replies: queue.Queue[dict[str, Any]] = queue.Queue()
    roslibpy.Topic(ros_world, "/c2rviz/reply", "std_msgs/String").subscribe(replies.put)
    ask(command_service(ros_world), "help")  # the subscription is in place once this returns
    command = roslibpy.Topic(ros_world, "/c2rviz/command", "std_msgs/msg/String")
    for i in range(8):
        command.publish(roslibpy.Message({"data": f"joints {i / 100},0,0,0,0,0,0"}))
    command.publish(roslibpy.Message({"data": "where"}))
    got = [replies.get(timeout=WAIT_S)["data"] for _ in range(9)]
    assert got == ["ok"] * 8 + ["ok 0.07,0,0,0,0,0,0"]


def test_an_error_reaches_a_roslibpy_user_on_the_reply_topic(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    """39.6: roslibpy drops ``status`` frames ("No handler registered for operation
    status"), so a refused publish was never seen; it is on /c2rviz/reply too now."""
    replies: queue.Queue[dict[str, Any]] = queue.Queue()
    roslibpy.Topic(ros_world, "/c2rviz/reply", "std_msgs/String").subscribe(replies.put)
    ask(command_service(ros_world), "help")  # the subscription is in place once this returns
    joints = roslibpy.Topic(ros_world, "/joint_command", "sensor_msgs/msg/JointState")
    joints.publish(roslibpy.Message({"name": ["joint_s", "elbow"], "position": [0.5, 0.5]}))
    refused = replies.get(timeout=WAIT_S)["data"]
    assert refused.startswith("error: publish /joint_command: ")
    assert "'elbow' is not a joint of motoman_sia20d's chain" in refused
    nowhere = roslibpy.Topic(ros_world, "/no_such_topic", "std_msgs/msg/String")
    nowhere.publish(roslibpy.Message({"data": "x"}))  # roslibpy advertises it first
    assert replies.get(timeout=WAIT_S)["data"].startswith("error: advertise: no topic /no_such")
    assert replies.get(timeout=WAIT_S)["data"].startswith("error: publish /no_such_topic: ")
    command = roslibpy.Topic(ros_world, "/c2rviz/command", "std_msgs/msg/String")
    command.publish(roslibpy.Message({"data": "joints 9,9,9,9,9,9,9"}))  # the line's own reply
    command.publish(roslibpy.Message({"data": "where"}))
    assert replies.get(timeout=WAIT_S)["data"].startswith("error: joint_s (index 0) = 9 rad")
    assert replies.get(timeout=WAIT_S)["data"].startswith("ok ")  # said once, not twice
    assert world_server.q() == load_robot("motoman_sia20d").home


def test_a_failed_service_call_raises_in_roslibpy(ros_world: roslibpy.Ros) -> None:
    """39.6, the other place a roslibpy user reads: the service response (result false)."""
    with pytest.raises(roslibpy.core.ServiceException, match="command is missing"):
        command_service(ros_world).call(roslibpy.ServiceRequest({}), timeout=WAIT_S)
    answer = ask(command_service(ros_world), "fly away")
    assert answer["ok"] is False and answer["reply"].startswith("error: unknown command 'fly'")


def server_side(server: ServerThread) -> Any:
    """The server's websocket of its one connection."""
    return server.call(lambda: next(iter(server.server._connections)).websocket)


def test_a_client_that_never_reads_holds_the_stop_for_the_close_timeout_only() -> None:
    """39.9: a client that never reads held the program's stop 12.5-20 s (a send blocked on
    it holds websockets' close until its keepalive gives up); now the closing handshake
    may take ``CLOSE_TIMEOUT_S`` (the text port's 1 s), then the connection is dropped,
    and the stop goes through with such a client connected (its time: docs/limits.md)."""
    server = ServerThread(CounterBridge(), RosbridgePolicy())
    stuck = connect(server.url, open_timeout=WAIT_S, max_queue=1, close_timeout=60)
    try:
        stuck.send(json.dumps({"op": "subscribe", "topic": "/counter"}))
        assert server.bridge.subscribed.get(timeout=WAIT_S) == "/counter"
        ticks = 0
        while server.server.stats["thinned"] == 0:  # until the socket buffers are full
            server.call(server.bridge.tick, 1, 65_536)
            ticks += 1
            assert ticks < 20_000, "the outbox never thinned"
        assert server_side(server).close_timeout == CLOSE_TIMEOUT_S == 1.0
    finally:
        server.stop()  # returns once the stuck client is dropped
        stuck.close_socket()
    assert server.server.connections == 0


def test_frames_sent_while_a_call_waits_are_read_ahead_a_bounded_few(
    rosbridge: ServerThread, bridge: CounterBridge
) -> None:
    """39.8: while a service call waited, websockets read ahead 16 frames (16 MiB at
    1 MiB each, per connection). Now reading stops past ``max_read_ahead`` frames and
    resumes when the connection catches up; every frame is still served, in order."""
    rosbridge.call(bridge.release.clear)  # "hold" waits until released
    frames = 12
    with connect(rosbridge.url, open_timeout=WAIT_S, max_size=None) as client:
        hold = {"op": "call_service", "id": "h", "service": "/c2rviz/command"}
        client.send(json.dumps(hold | {"args": {"command": "hold"}}))
        assert bridge.calls.get(timeout=WAIT_S) == "hold"
        big = {"op": "publish", "topic": "/inbox"}
        sender = threading.Thread(
            target=lambda: [
                client.send(json.dumps(big | {"msg": {"data": f"{i} " + "x" * 500_000}}))
                for i in range(frames)
            ],
            daemon=True,
        )
        sender.start()
        websocket = server_side(rosbridge)
        deadline = time.monotonic() + WAIT_S
        while not rosbridge.call(lambda: websocket.recv_messages.paused):
            assert time.monotonic() < deadline, "the server never stopped reading"
            time.sleep(0.01)
        queued = rosbridge.call(lambda: len(websocket.recv_messages.frames))
        limit = rosbridge.server.policy.max_read_ahead
        assert limit == 2 and queued <= limit + 1  # the limit, and the frame that passed it
        rosbridge.call(bridge.release.set)
        sender.join(WAIT_S)
        got = [bridge.published.get(timeout=WAIT_S)[2].split(" ", 1)[0] for _ in range(frames)]
        assert got == [str(i) for i in range(frames)]
        assert json.loads(client.recv(timeout=WAIT_S))["values"] == {
            "reply": "did hold",
            "ok": True,
        }


def test_the_docs_way_to_see_errors_works_as_written(ros_world: roslibpy.Ros) -> None:
    """39.6's docs: the snippet of docs/rosbridge.md that subscribes to the reply topic,
    run as written, prints the error its comment shows."""
    page = (ROOT / "docs" / "rosbridge.md").read_text()
    block = next(b for b in re.findall(r"```python\n(.*?)```", page, re.DOTALL) if "reply" in b)
    shown = [line.removeprefix("# ") for line in block.splitlines() if line.startswith("# error")]
    printed: queue.Queue[str] = queue.Queue()
    exec(block, {"roslibpy": roslibpy, "ros": ros_world, "print": printed.put})  # noqa: S102
    ask(command_service(ros_world), "help")  # the subscription is in place once this returns
    joints = roslibpy.Topic(ros_world, "/joint_command", "sensor_msgs/msg/JointState")
    joints.publish(roslibpy.Message({"name": ["joint_s", "elbow"], "position": [0.5, 0.5]}))
    line = printed.get(timeout=WAIT_S)
    pattern = ".*".join(re.escape(part) for part in shown[0].split("..."))
    assert re.fullmatch(pattern, line), (line, shown)
