"""rosapi answers from a table, the .msg texts, and the door's policy (all pure)."""

from __future__ import annotations

import json

import pytest

from c2rviz.transports.rosbridge.policy import PolicyError, RosbridgePolicy
from c2rviz.transports.rosbridge.rosapi import (
    DEFINITIONS,
    ROSAPI_SERVICES,
    Graph,
    RosapiError,
    answer,
    dependencies,
    full_text,
    is_rosapi,
)

URDF = '<robot name="arm"><link name="base"/></robot>'
GRAPH = Graph(
    topics=(
        ("/joint_states", "sensor_msgs/msg/JointState"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/c2rviz/events", "std_msgs/msg/String"),
        ("/visualization_marker_array", "visualization_msgs/msg/MarkerArray"),
        ("/joint_trajectory", "trajectory_msgs/msg/JointTrajectory"),
        ("/other", "other_msgs/msg/Unknown"),
    ),
    services=(("/c2rviz/command", "c2rviz_msgs/srv/Command"),),
    params={"robot_description": URDF},
)


def test_topics_and_types() -> None:
    values = answer("/rosapi/topics", {}, GRAPH)
    assert values["topics"][:2] == ["/joint_states", "/tf"]
    assert values["types"][:2] == ["sensor_msgs/msg/JointState", "tf2_msgs/msg/TFMessage"]


def test_topics_and_raw_types_has_a_definition_per_topic() -> None:
    values = answer("/rosapi/topics_and_raw_types", {}, GRAPH)
    assert len(values["typedefs_full_text"]) == len(values["topics"]) == 6
    joint_state = values["typedefs_full_text"][0]
    assert joint_state.startswith("std_msgs/Header header\n")
    assert "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" in joint_state
    assert joint_state.endswith("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n")
    assert values["typedefs_full_text"][-1] == ""  # a type c2rviz does not know


@pytest.mark.parametrize(
    ("service", "args", "values"),
    [
        ("/rosapi/topic_type", {"topic": "/tf"}, {"type": "tf2_msgs/msg/TFMessage"}),
        ("/rosapi/topic_type", {"topic": "tf"}, {"type": "tf2_msgs/msg/TFMessage"}),
        ("/rosapi/topic_type", {"topic": "/nope"}, {"type": ""}),
        ("/rosapi/topics_for_type", {"type": "std_msgs/String"}, {"topics": ["/c2rviz/events"]}),
        ("/rosapi/topics_for_type", {"type": "nonsense"}, {"topics": []}),
        (
            "/rosapi/service_type",
            {"service": "/c2rviz/command"},
            {"type": "c2rviz_msgs/srv/Command"},
        ),
        ("/rosapi/service_type", {"service": "/rosapi/nodes"}, {"type": "rosapi_msgs/srv/Nodes"}),
        ("/rosapi/nodes", {}, {"nodes": ["/c2rviz"]}),
        ("/rosapi/get_param", {"name": "robot_description"}, {"value": json.dumps(URDF)}),
        ("/rosapi/get_param", {"name": "/robot_description"}, {"value": json.dumps(URDF)}),
        (
            "/rosapi/get_param",
            {"name": "/robot_state_publisher:robot_description", "default_value": ""},
            {"value": json.dumps(URDF)},
        ),
        ("/rosapi/get_param", {"name": "rate", "default_value": "10"}, {"value": "10"}),
        ("/rosapi/has_param", {"name": "robot_description"}, {"exists": True}),
        ("/rosapi/has_param", {"name": "rate"}, {"exists": False}),
        ("/rosapi/get_param_names", {}, {"names": ["/c2rviz:robot_description"]}),
    ],
)
def test_rosapi_answers(service: str, args: dict[str, object], values: object) -> None:
    assert is_rosapi(service)
    assert answer(service, args, GRAPH) == values


def test_services_lists_c2rvizs_and_rosapis() -> None:
    services = answer("/rosapi/services", {}, GRAPH)["services"]
    assert services == ["/c2rviz/command", *ROSAPI_SERVICES]


@pytest.mark.parametrize(
    ("service", "args", "problem"),
    [
        (
            "/rosapi/get_param",
            {"name": "rate"},
            "no parameter 'rate' (parameters: robot_description)",
        ),
        ("/rosapi/topic_type", {"topic": 5}, "/rosapi/topic_type: topic must be a string"),
        ("/rosapi/delete_param", {}, "/rosapi/delete_param is not a rosapi service c2rviz answers"),
    ],
)
def test_rosapi_refusals(service: str, args: dict[str, object], problem: str) -> None:
    with pytest.raises(RosapiError, match=problem.replace("(", r"\(").replace(")", r"\)")):
        answer(service, args, GRAPH)


def test_every_definition_uses_only_defined_types() -> None:
    for name in DEFINITIONS:
        for used in dependencies(name):
            assert used in DEFINITIONS, f"{name} uses {used}"


def test_full_text_follows_rosapis_order() -> None:
    """rosapi walks dependencies with a stack: the last field's type comes first."""
    text = full_text("tf2_msgs/TFMessage")
    order = [line[5:] for line in text.splitlines() if line.startswith("MSG: ")]
    assert order == [
        "geometry_msgs/TransformStamped",
        "geometry_msgs/Transform",
        "geometry_msgs/Quaternion",
        "geometry_msgs/Vector3",
        "std_msgs/Header",
        "builtin_interfaces/Time",
    ]
    assert full_text("tf2_msgs/msg/TFMessage") == text
    marker_array = full_text("visualization_msgs/msg/MarkerArray")
    assert marker_array.count("MSG: ") == len(set(marker_array.split("MSG: ")[1:]))  # each once


@pytest.mark.parametrize(
    ("origin", "allowed"),
    [
        (None, True),
        ("http://localhost:5173", True),
        ("https://LOCALHOST", True),
        ("http://127.0.0.1:8080", True),
        ("http://[::1]:9000", True),
        ("https://dash.example.org", True),
        ("https://dash.example.org:443/", True),
        ("http://dash.example.org", False),
        ("http://localhost.evil.com", False),
        ("http://user@localhost", False),
        ("file://", False),
        ("null", False),
    ],
)
def test_origins(origin: str | None, allowed: bool) -> None:
    assert RosbridgePolicy(("https://dash.example.org",)).origin_ok(origin) is allowed


def test_token() -> None:
    policy = RosbridgePolicy(token="abc")
    assert policy.token_ok("/?token=abc") and not policy.token_ok("/?token=abd")
    assert not policy.token_ok("/") and RosbridgePolicy().token_ok("/")


@pytest.mark.parametrize(
    ("settings", "problem"),
    [
        ({"extra_origins": ("dash.example.org",)}, "is not scheme://host[:port]"),
        ({"token": ""}, "token '' is not non-empty printable ASCII"),
        ({"max_connections": 0}, "max connections '0' is not at least 1"),
        ({"max_frame_bytes": 0}, "max frame bytes '0' is not at least 1"),
    ],
)
def test_a_policy_that_cannot_work_is_refused(settings: dict[str, object], problem: str) -> None:
    with pytest.raises(PolicyError, match=problem.replace("[", r"\[").replace("]", r"\]")):
        RosbridgePolicy(**settings)  # type: ignore[arg-type]
