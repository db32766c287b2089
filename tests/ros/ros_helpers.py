"""Shared pieces of the ROS tests: robots, random messages, and bags written with rosbags itself.

(Not a conftest.py: tests/conftest.py is imported as ``conftest`` by the other tests.)
"""

from __future__ import annotations

import importlib.metadata
import math
import string
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.interfaces import Nodetype
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from c2rviz.robot import Robot

ROOT = Path(__file__).resolve().parents[2]
TREE = ROOT / "tests" / "data" / "tree_robot" / "tree.urdf"
BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}
HUMBLE = get_typestore(Stores.ROS2_HUMBLE)
NOETIC = get_typestore(Stores.ROS1_NOETIC)
JOINT_STATE = "sensor_msgs/msg/JointState"


@cache
def bundled(name: str) -> Robot:
    path, base, eelink = BUNDLED[name]
    return Robot.from_urdf(ROOT / path, base, eelink)


@cache
def tree_robot() -> Robot:
    """Prismatic lift, continuous wrist, a mimic finger (x-1, +0.002 m) and a fixed mast."""
    return Robot.from_urdf(TREE, "base_link", "tool0")


def panda_urdf() -> Path | None:
    """example-robot-data's panda URDF, if that package is installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for file in dist.files or ():
        if str(file).endswith("panda_description/urdf/panda.urdf"):
            return Path(str(dist.locate_file(file)))
    return None


@cache
def panda() -> Robot:
    """Panda arm to its hand's TCP: fingers, a mimic finger, three fixed joints."""
    path = panda_urdf()
    if path is None:
        pytest.skip("example-robot-data is not installed")
    return Robot.from_urdf(path, "panda_link0", "panda_hand_tcp")


def robot_named(name: str) -> Robot:
    return {"tree": tree_robot, "panda": panda}.get(name, lambda: bundled(name))()


ROBOTS = [*BUNDLED, "tree", "panda"]


# --- random messages of any type ---------------------------------------------------

_RANGES = {
    "bool": (0, 1),
    "byte": (0, 127),  # an octet in ROS 2; rosbags reads it back signed, so stay below 128
    "char": (0, 255),
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 255),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}


def random_value(desc: tuple[Any, Any], rng: np.random.Generator, depth: int = 0) -> Any:
    kind, args = desc
    if kind == Nodetype.BASE:
        name = args[0]
        if name == "string":
            letters = string.ascii_letters + "éß/_ "
            return "".join(rng.choice(list(letters), int(rng.integers(0, 12))))
        if name in ("float32", "float64"):
            return float(rng.normal() * 10 ** int(rng.integers(-3, 4)))
        low, high = _RANGES[name]
        value = int(
            rng.integers(low, high, endpoint=True, dtype=np.int64 if high < 2**63 else np.uint64)
        )
        return bool(value) if name == "bool" else value
    if kind == Nodetype.NAME:
        return random_message(args, rng, depth + 1)
    inner, length = args
    n = int(length) if kind == Nodetype.ARRAY else int(rng.integers(0, 4 if depth < 3 else 1))
    return [random_value(inner, rng, depth + 1) for _ in range(n)]


def random_message(msgtype: str, rng: np.random.Generator, depth: int = 0) -> dict[str, Any]:
    """A dict of ``msgtype`` (Humble) with random values in every field."""
    return {name: random_value(desc, rng, depth) for name, desc in HUMBLE.fielddefs[msgtype][1]}


def as_plain(value: Any) -> Any:
    """A rosbags message object as nested dicts and lists (for comparisons)."""
    if hasattr(value, "__dataclass_fields__"):
        return {
            k: as_plain(getattr(value, k)) for k in value.__dataclass_fields__ if k != "__msgtype__"
        }
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [as_plain(v) for v in value]
    return value


# --- bags written with rosbags itself --------------------------------------------

JointSample = tuple[float, Sequence[str], Sequence[float]]
"""(time [s], names, positions) of one JointState to write."""


def humble_joint_state(names: Sequence[str], positions: Sequence[float], stamp_ns: int) -> Any:
    types = HUMBLE.types
    time = types["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    return types[JOINT_STATE](
        header=types["std_msgs/msg/Header"](stamp=time, frame_id=""),
        name=list(names),
        position=np.array(positions, dtype=np.float64),
        velocity=np.array([], dtype=np.float64),
        effort=np.array([], dtype=np.float64),
    )


def write_rosbag2(
    path: Path,
    topics: dict[str, Iterable[JointSample]],
    others: Iterable[tuple[str, str, float, Any]] = (),
    storage: StoragePlugin = StoragePlugin.MCAP,
    stamps: dict[float, int] | None = None,
) -> Path:
    """A rosbag2 bag (rosbags' writer): JointState topics, and (topic, type, t, message) others.

    The header stamp of each JointState is its time, unless ``stamps`` maps the time
    to another stamp [ns].
    """
    with Writer(path, version=9, storage_plugin=storage) as writer:
        for topic, samples in topics.items():
            conn = writer.add_connection(topic, JOINT_STATE, typestore=HUMBLE)
            for t, names, positions in samples:
                stamp = (stamps or {}).get(t, round(t * 1e9))
                raw = HUMBLE.serialize_cdr(humble_joint_state(names, positions, stamp), JOINT_STATE)
                writer.write(conn, round(t * 1e9), raw)
        added: dict[str, Any] = {}
        for topic, msgtype, t, message in others:
            if topic not in added:
                added[topic] = writer.add_connection(topic, msgtype, typestore=HUMBLE)
            writer.write(added[topic], round(t * 1e9), HUMBLE.serialize_cdr(message, msgtype))
    return path


def write_rosbag1(path: Path, topic: str, samples: Iterable[JointSample]) -> Path:
    """A ROS 1 bag (rosbags' rosbag1 writer) with one sensor_msgs/JointState topic."""
    types = NOETIC.types
    msgtype = "sensor_msgs/msg/JointState"
    with Writer1(path) as writer:
        conn = writer.add_connection(topic, msgtype, typestore=NOETIC)
        for seq, (t, names, positions) in enumerate(samples):
            ns = round(t * 1e9)
            time = types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            message = types[msgtype](
                header=types["std_msgs/msg/Header"](seq=seq, stamp=time, frame_id=""),
                name=list(names),
                position=np.array(positions, dtype=np.float64),
                velocity=np.array([], dtype=np.float64),
                effort=np.array([], dtype=np.float64),
            )
            writer.write(conn, ns, NOETIC.serialize_ros1(message, msgtype))
    return path


def sweep(names: Sequence[str], n: int, rate_hz: float = 100.0) -> list[JointSample]:
    """``n`` samples at ``rate_hz`` whose joint k is ``0.1 k + sin(t)``."""
    return [
        (i / rate_hz, names, [0.1 * k + math.sin(i / rate_hz) for k in range(len(names))])
        for i in range(n)
    ]
