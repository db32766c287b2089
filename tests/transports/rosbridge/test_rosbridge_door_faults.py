"""Issue 39's faults at the rosbridge door (5, 6, 7, 8, 9), each through a real server."""

from __future__ import annotations

import queue
from typing import Any

import pytest
import roslibpy
from support import load_robot
from world_support import WAIT_S, WorldServer, ask, command_service

from c2rviz.transports.rosbridge.messages import MessageError, joint_positions, joint_trajectory

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
