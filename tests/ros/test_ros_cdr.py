"""The dict -> CDR encoder agrees with rosbags byte for byte, on every ROS 2 Humble type."""

from __future__ import annotations

import base64

import numpy as np
import pytest
from ros_helpers import HUMBLE, as_plain, random_message

from c2rviz.ros.cdr import CdrEncoder
from c2rviz.ros.errors import MessageError

ENCODER = CdrEncoder(HUMBLE)
TYPES = sorted(HUMBLE.fielddefs)


@pytest.mark.parametrize("msgtype", TYPES)
def test_every_type_encodes_as_rosbags_does(msgtype: str) -> None:
    """Random values in every field: rosbags reads them back, and writes the same bytes."""
    rng = np.random.default_rng(sum(map(ord, msgtype)))
    for _ in range(3):
        message = random_message(msgtype, rng)
        ours = bytes(ENCODER.encode(msgtype, message))
        decoded = HUMBLE.deserialize_cdr(ours, msgtype)
        assert bytes(HUMBLE.serialize_cdr(decoded, msgtype)) == ours
        back = as_plain(decoded)
        for name, value in message.items():
            if not isinstance(value, float):  # float32 fields round; their bytes matched above
                assert back[name] == value or isinstance(back[name], (dict, list)), name


def test_numeric_arrays_as_numpy_bytes_and_base64() -> None:
    image = {
        "header": {"stamp": {"sec": 1, "nanosec": 2}, "frame_id": "cam"},
        "height": 1,
        "width": 3,
        "encoding": "mono8",
        "is_bigendian": 0,
        "step": 3,
        "data": [1, 2, 255],
    }
    as_list = bytes(ENCODER.encode("sensor_msgs/msg/Image", image))
    for data in (bytes([1, 2, 255]), base64.b64encode(bytes([1, 2, 255])).decode()):
        assert bytes(ENCODER.encode("sensor_msgs/msg/Image", {**image, "data": data})) == as_list
    state = {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
        "name": ["a", "b"],
        "position": [0.5, 1.5],
        "velocity": [],
        "effort": [],
    }
    as_floats = bytes(ENCODER.encode("sensor_msgs/msg/JointState", state))
    with_numpy = {**state, "position": np.array([0.5, 1.5]), "velocity": np.empty(0)}
    assert bytes(ENCODER.encode("sensor_msgs/msg/JointState", with_numpy)) == as_floats


def test_an_empty_type_takes_an_empty_dict() -> None:
    """rosbridge sends std_msgs/Empty as {}; rosbags' stand-in field is not asked for."""
    ours = bytes(ENCODER.encode("std_msgs/msg/Empty", {}))
    assert ours == bytes(
        HUMBLE.serialize_cdr(HUMBLE.types["std_msgs/msg/Empty"](), "std_msgs/msg/Empty")
    )


@pytest.mark.parametrize(
    ("msgtype", "message", "problem"),
    [
        ("std_msgs/msg/Nothing", {}, "unknown message type"),
        ("std_msgs/msg/String", {}, "lacks field 'data'"),
        ("std_msgs/msg/String", {"data": 3}, "does not fit"),
        ("std_msgs/msg/Int32", {"data": 2**31}, "does not fit"),
        ("std_msgs/msg/Float64", {"data": "1.0"}, "does not fit"),
        ("geometry_msgs/msg/Vector3", {"x": 1.0, "y": 2.0}, "lacks field 'z'"),
        (
            "geometry_msgs/msg/PoseWithCovariance",
            {
                "pose": {
                    "position": {"x": 0, "y": 0, "z": 0},
                    "orientation": {"x": 0, "y": 0, "z": 0, "w": 1},
                },
                "covariance": [0.0] * 35,
            },
            "35 values for an array of 36",
        ),
        (
            "sensor_msgs/msg/Image",
            {
                "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
                "height": 0,
                "width": 0,
                "encoding": "",
                "is_bigendian": 0,
                "step": 0,
                "data": "not base64!",
            },
            "does not fit",
        ),
    ],
    ids=["type", "missing", "string", "int32", "float", "nested", "array-length", "base64"],
)
def test_bad_messages(msgtype: str, message: dict[str, object], problem: str) -> None:
    with pytest.raises(MessageError, match=problem):
        ENCODER.encode(msgtype, message)


def test_generated_source_holds_no_message_text() -> None:
    """The compiled source is made of keys, struct codes and locals only."""
    source = ENCODER.compile("visualization_msgs/msg/MarkerArray").__doc__ or ""
    assert "def encode(buf, message):" in source
    assert "exec" not in source and "import" not in source
