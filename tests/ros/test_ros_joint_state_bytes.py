"""The quick JointState decoder reads what rosbags writes, in CDR and in ROS 1 serialization."""

from __future__ import annotations

import numpy as np
import pytest
from ros_helpers import HUMBLE, JOINT_STATE, NOETIC, humble_joint_state

from c2rviz.ros.cdr import JointStateDecoder

NAMES = [
    ("a",),
    ("joint_1", "joint_2", "joint_3"),
    ("joint_1", "joint_2", "joint_3"),
    ("é", "bb", ""),
    (),
]


def ros1_state(names: tuple[str, ...], positions: list[float], stamp_ns: int) -> bytes:
    types = NOETIC.types
    time = types["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    message = types[JOINT_STATE](
        header=types["std_msgs/msg/Header"](seq=7, stamp=time, frame_id="frame"),
        name=list(names),
        position=np.array(positions),
        velocity=np.array(positions),
        effort=np.empty(0),
    )
    return bytes(NOETIC.serialize_ros1(message, JOINT_STATE))


@pytest.mark.parametrize("ros1", [False, True], ids=["cdr", "ros1"])
def test_decodes_what_rosbags_writes(ros1: bool) -> None:
    decoder = JointStateDecoder(ros1=ros1)
    rng = np.random.default_rng(4)
    for k, names in enumerate([*NAMES, *NAMES]):  # names repeat, change, and come back
        positions = rng.normal(size=len(names)).tolist()
        stamp = 1_700_000_000_123_456_789 + k
        if ros1:
            raw = ros1_state(names, positions, stamp)
        else:
            state = humble_joint_state(names, positions, stamp)
            state.header.frame_id = "f" * (k % 5)  # every alignment of what follows
            raw = bytes(HUMBLE.serialize_cdr(state, JOINT_STATE))
        assert decoder.decode(raw) == (stamp, names, tuple(positions))


def test_big_endian_cdr_is_left_to_rosbags() -> None:
    state = humble_joint_state(("a",), [1.0], 5)
    raw = bytes(HUMBLE.serialize_cdr(state, JOINT_STATE, little_endian=False))
    assert JointStateDecoder().decode(raw) is None


@pytest.mark.parametrize("ros1", [False, True], ids=["cdr", "ros1"])
def test_cut_short(ros1: bool) -> None:
    names = ("joint_1", "joint_2")
    if ros1:
        raw = ros1_state(names, [1.0, 2.0], 0)
    else:
        raw = bytes(HUMBLE.serialize_cdr(humble_joint_state(names, [1.0, 2.0], 0), JOINT_STATE))
    for cut in (20, 30, len(raw) - 30):
        with pytest.raises(ValueError):
            JointStateDecoder(ros1=ros1).decode(raw[:cut])
