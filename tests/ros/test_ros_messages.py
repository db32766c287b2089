"""The message builders: the dict shapes rosbridge sends, complete for ROS 2 Humble's types."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from ros_helpers import HUMBLE, as_plain

from c2rviz.ros import messages as m
from c2rviz.ros import messages as mk
from c2rviz.ros.cdr import CdrEncoder
from c2rviz.ros.errors import MessageError

ENCODER = CdrEncoder(HUMBLE)


def round_trip(msgtype: str, message: dict[str, Any]) -> Any:
    """Encode with ours, decode with rosbags: every field must be there and fit."""
    return as_plain(HUMBLE.deserialize_cdr(bytes(ENCODER.encode(msgtype, message)), msgtype))


@pytest.mark.parametrize(
    ("t_s", "sec", "nanosec"),
    [
        (0.0, 0, 0),
        (1.5, 1, 500_000_000),
        (1e-9, 0, 1),
        (0.9999999999, 1, 0),  # rounds to the nearest nanosecond, carrying
        (-0.5, -1, 500_000_000),  # ROS time: sec floors, nanosec is never negative
        (1_700_000_000.25, 1_700_000_000, 250_000_000),
    ],
    ids=["zero", "half", "one-ns", "carry", "negative", "epoch"],
)
def test_stamp(t_s: float, sec: int, nanosec: int) -> None:
    assert m.stamp(t_s) == {"sec": sec, "nanosec": nanosec}


@pytest.mark.parametrize("t_s", [math.nan, math.inf, -math.inf, 2.0**31, -(2.0**31) - 1])
def test_stamp_refuses_what_ros_time_cannot_hold(t_s: float) -> None:
    with pytest.raises(MessageError, match="not a ROS time"):
        m.stamp(t_s)


@pytest.mark.parametrize(
    ("namespace", "prefix", "joint_states"),
    [
        ("", "", "/joint_states"),
        ("left", "left/", "/left/joint_states"),
        ("r2_b", "r2_b/", "/r2_b/joint_states"),
    ],
    ids=["alone", "left", "underscore"],
)
def test_namespaces(namespace: str, prefix: str, joint_states: str) -> None:
    assert m.frame_prefix(namespace) == prefix
    assert m.topic(namespace, "joint_states") == joint_states


@pytest.mark.parametrize("namespace", ["2left", "a/b", "le ft", "/left", "é"])
def test_bad_namespaces(namespace: str) -> None:
    with pytest.raises(MessageError, match="not a ROS name"):
        m.frame_prefix(namespace)


def test_joint_state_shape() -> None:
    message = m.joint_state(2.25, ["a", "b"], [0.5, -1], [0.1, 0.2], frame_id="base")
    assert message == {
        "header": {"stamp": {"sec": 2, "nanosec": 250_000_000}, "frame_id": "base"},
        "name": ["a", "b"],
        "position": [0.5, -1.0],
        "velocity": [0.1, 0.2],
        "effort": [],
    }
    assert round_trip(m.JOINT_STATE, message) == message


@pytest.mark.parametrize(
    ("positions", "velocities", "efforts", "problem"),
    [
        ([0.0], (), (), "1 positions for 2 names"),
        ([0.0, 1.0], [0.0], (), "1 velocities for 2 names"),
        ([0.0, 1.0], (), [1, 2, 3], "3 efforts for 2 names"),
    ],
    ids=["positions", "velocities", "efforts"],
)
def test_joint_state_lengths(
    positions: list[float], velocities: Any, efforts: Any, problem: str
) -> None:
    with pytest.raises(MessageError, match=problem):
        m.joint_state(0.0, ["a", "b"], positions, velocities, efforts)


def test_transform_and_tf_message() -> None:
    one = m.transform(1.0, "base_link", "link_1", (1, 2, 3), (0, 0, 0.6, 0.8))
    assert one == {
        "header": {"stamp": {"sec": 1, "nanosec": 0}, "frame_id": "base_link"},
        "child_frame_id": "link_1",
        "transform": {
            "translation": {"x": 1.0, "y": 2.0, "z": 3.0},
            "rotation": {"x": 0.0, "y": 0.0, "z": 0.6, "w": 0.8},
        },
    }
    items = [
        ("a", "b", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0)),
        ("b", "c", (0.0, 0.0, 1.0), (1.0, 0, 0, 0)),
    ]
    assert m.transforms(1.0, items) == [m.transform(1.0, *item) for item in items]
    message = m.tf_message(m.transforms(1.0, items))
    assert round_trip(m.TF_MESSAGE, message) == json.loads(json.dumps(message))


def test_string() -> None:
    assert round_trip(m.STRING, m.string("move 1 2 3 # ü")) == {"data": "move 1 2 3 # ü"}


@pytest.mark.parametrize(
    ("shape", "size", "kind", "scale"),
    [
        ("box", (0.1, 0.2, 0.3), mk.CUBE, (0.1, 0.2, 0.3)),
        ("sphere", (0.25,), mk.SPHERE, (0.5, 0.5, 0.5)),
        ("cylinder", (0.05, 0.4), mk.CYLINDER, (0.1, 0.1, 0.4)),
        ("mesh", (1.0, 2.0, 1.0), mk.MESH_RESOURCE, (1.0, 2.0, 1.0)),
    ],
    ids=["box", "sphere", "cylinder", "mesh"],
)
def test_object_markers(
    shape: str, size: tuple[float, ...], kind: int, scale: tuple[float, ...]
) -> None:
    marker = mk.object_marker(
        3.0,
        "base_link",
        f"workcell/{shape}",
        0,
        shape,
        size,
        (1, 2, 3),
        (0, 0, 0, 1),
        (1, 0, 0, 0.5),
        mesh_uri="file:///tmp/part.stl",
    )
    assert marker["type"] == kind and marker["action"] == mk.ADD
    assert (marker["scale"]["x"], marker["scale"]["y"], marker["scale"]["z"]) == scale
    assert marker["mesh_resource"] == ("file:///tmp/part.stl" if shape == "mesh" else "")
    decoded = round_trip(mk.MARKER_ARRAY, mk.marker_array([marker]))["markers"][0]
    assert decoded["ns"] == f"workcell/{shape}" and decoded["header"]["frame_id"] == "base_link"
    assert decoded["pose"]["position"] == {"x": 1.0, "y": 2.0, "z": 3.0}
    assert decoded["color"] == {"r": 1.0, "g": 0.0, "b": 0.0, "a": 0.5}


@pytest.mark.parametrize("shape", ["sphere", "cube", "arrow", "cylinder"])
def test_c2rviz_marker_shapes(shape: str) -> None:
    marker = mk.marker(1.0, "world", "markers", 7, mk.SHAPES[shape], (0, 0, 1), scale=(0.02,) * 3)
    assert (
        round_trip(mk.MARKER_ARRAY, mk.marker_array([marker]))["markers"][0]["type"]
        == mk.SHAPES[shape]
    )


def test_deletions() -> None:
    delete = mk.delete_marker(5.0, "world", "markers", 7)
    everything = mk.delete_all(5.0)
    assert (delete["action"], delete["ns"], delete["id"]) == (mk.DELETE, "markers", 7)
    assert (everything["action"], everything["ns"]) == (mk.DELETEALL, "")
    decoded = round_trip(mk.MARKER_ARRAY, mk.marker_array([delete, everything]))
    assert [x["action"] for x in decoded["markers"]] == [2, 3]


@pytest.mark.parametrize(
    ("call", "problem"),
    [
        (
            lambda: mk.object_marker(
                0, "f", "n", 0, "cone", (1,), (0, 0, 0), (0, 0, 0, 1), (1, 1, 1, 1)
            ),
            "not one of",
        ),
        (
            lambda: mk.object_marker(
                0, "f", "n", 0, "box", (1, 2), (0, 0, 0), (0, 0, 0, 1), (1, 1, 1, 1)
            ),
            "takes 3",
        ),
        (lambda: mk.marker(0, "f", "n", 0, 42), "shape 42"),
        (lambda: mk.marker(0, "f", "n", 0, mk.CUBE, action=1), "action 1"),
        (lambda: mk.marker(0, "f", "n", 2**31, mk.CUBE), "outside int32"),
    ],
    ids=["shape", "size", "marker-type", "action", "id"],
)
def test_bad_markers(call: Any, problem: str) -> None:
    with pytest.raises(MessageError, match=problem):
        call()


def test_every_builder_gives_json() -> None:
    """rosbridge sends these as JSON text: nothing in them may need more than JSON."""
    built = [
        m.joint_state(1.0, ["a"], [1.0]),
        m.tf_message([m.transform(1.0, "a", "b", (0, 0, 0), (0, 0, 0, 1))]),
        m.string("x"),
        mk.marker_array([mk.marker(1.0, "f", "n", 1, mk.SPHERE), mk.delete_all(1.0)]),
    ]
    for message in built:
        assert json.loads(json.dumps(message)) == message
