"""Type names and the messages c2rviz takes: tables of good and bad messages."""

from __future__ import annotations

from typing import Any

import pytest

from c2rviz.errors import C2rvizError
from c2rviz.transports.rosbridge.messages import (
    JOINT_TRAJECTORY,
    JointPositions,
    JointTrajectory,
    MessageError,
    TrajectoryOutline,
    TrajectoryPoint,
    TypeNameError,
    command_request,
    command_response,
    joint_positions,
    joint_trajectory,
    normalize_type,
    read_ahead,
    same_type,
    string_data,
)


@pytest.mark.parametrize(
    ("name", "kind", "normal"),
    [
        ("sensor_msgs/JointState", "msg", "sensor_msgs/msg/JointState"),
        ("sensor_msgs/msg/JointState", "msg", "sensor_msgs/msg/JointState"),
        ("rosapi/Topics", "srv", "rosapi/srv/Topics"),
        ("rosapi_msgs/srv/Topics", "srv", "rosapi_msgs/srv/Topics"),
    ],
)
def test_both_spellings_normalize(name: str, kind: str, normal: str) -> None:
    assert normalize_type(name, kind) == normal


@pytest.mark.parametrize(
    ("name", "kind", "problem"),
    [
        ("JointState", "msg", "is not a msg type name (package/Name or package/msg/Name)"),
        ("sensor_msgs/JointState/x", "msg", "is not a msg type name (package/Name or"),
        ("sensor msgs/JointState", "msg", "is not a msg type name"),
        ("", "msg", "is not a msg type name"),
        ("std_srvs/srv/Trigger", "msg", "is a srv type, not a msg type"),
        ("std_msgs/msg/String", "srv", "is a msg type, not a srv type"),
    ],
)
def test_a_bad_type_name_is_refused(name: str, kind: str, problem: str) -> None:
    with pytest.raises(TypeNameError) as refused:
        normalize_type(name, kind)
    assert str(refused.value).startswith(f"type {name!r} {problem}")


def test_same_type_across_spellings() -> None:
    assert same_type("tf2_msgs/TFMessage", "tf2_msgs/msg/TFMessage")
    assert not same_type("std_msgs/String", "std_msgs/msg/Header")


def test_string_data() -> None:
    assert string_data({"data": "joints 0 0 0"}) == "joints 0 0 0"


def test_a_joint_state_gives_positions_by_name() -> None:
    msg = {
        "header": {"stamp": {"sec": 1, "nanosec": 5}, "frame_id": ""},
        "name": ["joint_s", "joint_l"],
        "position": [0.5, -1],
        "velocity": [],
        "effort": [0.0, 1.0],
    }
    assert joint_positions(msg) == JointPositions(("joint_s", "joint_l"), (0.5, -1.0))


def point(t_s: float, *positions: float, **more: Any) -> dict[str, Any]:
    sec = int(t_s)
    nanosec = round((t_s - sec) * 1e9)
    return {
        "positions": list(positions),
        "time_from_start": {"sec": sec, "nanosec": nanosec},
    } | more


def test_a_trajectory_in_seconds() -> None:
    msg = {
        "joint_names": ["a", "b"],
        "points": [
            point(0.0, 0.0, 0.0),
            point(0.5, 0.1, 0.2, velocities=[1.0, 2.0], accelerations=[], effort=[]),
            point(2.25, 0.3, 0.4),
        ],
    }
    assert joint_trajectory(msg) == JointTrajectory(
        ("a", "b"),
        (
            TrajectoryPoint((0.0, 0.0), 0.0),
            TrajectoryPoint((0.1, 0.2), 0.5, velocities=(1.0, 2.0)),
            TrajectoryPoint((0.3, 0.4), 2.25),
        ),
    )


def test_a_trajectory_read_ahead_for_joints_it_lacks_is_its_outline() -> None:
    """Read off the loop for a robot's joints: a trajectory naming another comes back as
    its outline (names, count, last time), one naming only those whole; a message that
    does not fit its type is its error, whatever it names."""
    msg = {"joint_names": ["a", "x"], "points": [point(0.5, 0.1, 0.2), point(2.25, 0.3, 0.4)]}
    assert read_ahead(JOINT_TRAJECTORY, msg, ("a", "b")) == TrajectoryOutline(("a", "x"), 2, 2.25)
    assert read_ahead(JOINT_TRAJECTORY, msg, ("a", "x")) == joint_trajectory(msg)
    assert read_ahead(JOINT_TRAJECTORY, msg) == joint_trajectory(msg)
    msg["points"].append(point(1.0, 0.0, 0.0))
    error = read_ahead(JOINT_TRAJECTORY, msg, ("a", "b"))
    assert isinstance(error, MessageError) and "points[2].time_from_start" in str(error)


def test_the_command_service() -> None:
    assert command_request({"command": "home"}) == "home"
    assert command_response("ok", True) == {"reply": "ok", "ok": True}


JOINTS = ["a", "b"]
BAD: list[tuple[str, Any, str]] = [
    ("string", {}, "std_msgs/msg/String: data is missing"),
    ("string", {"data": 3}, "std_msgs/msg/String: data must be a string"),
    ("string", {"data": "x", "more": 1}, "has no field 'more' (fields: data)"),
    ("string", ["data"], "must be an object with fields data"),
    ("joints", {"position": [1.0]}, "sensor_msgs/msg/JointState: name must be a non-empty array"),
    ("joints", {"name": [], "position": []}, "name must be a non-empty array of joint names"),
    ("joints", {"name": ["a", 3], "position": [1, 2]}, "name[1] must be a string"),
    ("joints", {"name": ["a", "a"], "position": [1, 2]}, "name[1] repeats joint 'a'"),
    ("joints", {"name": ["a", ""], "position": [1, 2]}, "name[1] is empty"),
    ("joints", {"name": JOINTS}, "position must be an array of numbers"),
    ("joints", {"name": JOINTS, "position": [1.0]}, "position has 1 values for 2 joints"),
    ("joints", {"name": JOINTS, "position": [1.0, "2"]}, "position[1] must be a number"),
    ("joints", {"name": JOINTS, "position": [1.0, True]}, "position[1] must be a number"),
    ("joints", {"name": JOINTS, "position": [1.0, float("inf")]}, "position[1] is not finite"),
    ("joints", {"name": JOINTS, "position": [1, 2], "velocity": [1]}, "velocity has 1 values"),
    ("joints", {"name": JOINTS, "position": [1, 2], "speed": []}, "has no field 'speed'"),
    ("joints", {"name": JOINTS, "position": [1, 2], "header": 5}, "header must be an object"),
    (
        "joints",
        {"name": JOINTS, "position": [1, 2], "header": {"stamp": {"sec": 0, "nanosec": -1}}},
        "header.stamp.nanosec -1 is outside 0..999999999",
    ),
    ("trajectory", {"joint_names": JOINTS}, "points must be a non-empty array"),
    ("trajectory", {"joint_names": JOINTS, "points": []}, "points must be a non-empty array"),
    ("trajectory", {"points": [point(1, 0, 0)]}, "joint_names must be a non-empty array"),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [{"positions": [0, 0]}]},
        "trajectory_msgs/msg/JointTrajectory: points[0].time_from_start is missing",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, 0), point(2, 0, 0), point(3, 0)]},
        "points[2].positions has 1 values for 2 joints",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(0.5, 0, 0), point(1, 0, 0), point(1, 1, 1)]},
        "points[2].time_from_start is not after points[1]",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(2, 0, 0), point(1, 0, 0)]},
        "points[1].time_from_start is not after points[0]",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, float("nan"))]},
        "points[0].positions[1] is not finite",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, 0, velocities=[1.0])]},
        "points[0].velocities has 1 values for 2 joints",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, 0) | {"time_from_start": {"sec": -1}}]},
        "points[0].time_from_start.sec -1 is outside 0..2147483647",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, 0) | {"time_from_start": {"secs": 1}}]},
        "points[0].time_from_start has no field 'secs' (fields: sec, nanosec)",
    ),
    (
        "trajectory",
        {"joint_names": JOINTS, "points": [point(1, 0, 0) | {"time_from_start": 1.0}]},
        "points[0].time_from_start must be an object with fields sec, nanosec",
    ),
    ("command", {}, "c2rviz_msgs/srv/Command_Request: command is missing"),
    ("command", {"command": ["home"]}, "command must be a string"),
]
READERS = {
    "string": string_data,
    "joints": joint_positions,
    "trajectory": joint_trajectory,
    "command": command_request,
}


@pytest.mark.parametrize(("reader", "msg", "problem"), BAD, ids=[b[2] for b in BAD])
def test_a_bad_message_names_its_field(reader: str, msg: Any, problem: str) -> None:
    with pytest.raises(MessageError) as refused:
        READERS[reader](msg)
    assert isinstance(refused.value, C2rvizError)
    assert problem in str(refused.value)
