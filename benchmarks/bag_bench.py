"""What a rosbag2 bag costs to record beside the CSV, and what reading one back costs the player.

Run: ``python benchmarks/bag_bench.py [--quick] [--minutes M] [--keep DIR] [--ros1]``.

Writing (CPU time of this process, median of several runs, motoman_sia20d): the
cost of one 100 Hz frame for 1 and for 8 robots of

- ``csv``: what ``Recorder._frame`` does now per robot: the tool pose by forward
  kinematics, a ``joints`` line to the command file and a row to the ``.csv``,
  through 256 KiB buffers;
- ``bag``: ``BagRobot.frame`` per robot: ``/joint_states`` (every moving joint)
  and ``/tf`` (each moving joint's transform), dict messages encoded by
  ``CdrEncoder`` into one rosbag2 MCAP bag (robots namespaced ``r0``.. in a cell);
- ``objects``: the same two messages built as rosbags message objects and
  serialized with ``typestore.serialize_cdr`` (the road not taken, for comparison).

The goal (issue 25) is at most 10 % CPU more than recording without the bag at
100 Hz; the ``+core`` column is the bag's added CPU as a share of one core at
100 Hz, and ``bag/csv`` the bag's cost over the current CSV recording's own.

Reading: a bag like a c2rviz recording (``/joint_states`` and ``/tf`` of the
motoman at 100 Hz; 60 minutes, 6 with ``--quick``) is written once, then read
by a fresh process the way the player will: ``JointStateBag.open``, ``check`` of
the span, then the first sample (goals: 2 s for a 60 s span, 10 s for the whole
bag, the check included), then every sample to the span's end. Peak RSS of each
reading process is printed beside the bag's size: flat memory means the whole
bag peaks where 60 s of it does. ``--ros1`` reads a ROS 1 ``.bag`` of the same
joint states too (rosbags keeps a ROS 1 bag's message index in memory, so its
memory grows with the bag). Figures only: nothing here passes or fails.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.robot import Robot  # noqa: E402
from c2rviz.ros.bag_reader import JointStateBag  # noqa: E402
from c2rviz.ros.bag_writer import BagRobot, BagWriter  # noqa: E402

__all__ = ["main"]

URDF = ROOT / "robots" / "motoman_sia20d" / "robot.urdf"
RATE_HZ = 100.0


def load() -> Robot:
    return Robot.from_urdf(URDF, "base_link", "link_t")


def numbers(values: Sequence[float]) -> str:
    """As the recorder formats a row (replies.numbers: 10 significant digits)."""
    return ",".join([f"{v:.10g}" if abs(v) > 1e-9 else "0" for v in values])


class CsvRows:
    """One robot's current recording, as ``Recorder._frame`` writes it."""

    def __init__(self, robot: Robot, folder: Path, name: str) -> None:
        self.robot = robot
        self.tool = pin.SE3.Identity()
        self.body: TextIO = open(folder / f"{name}.txt", "w", buffering=1 << 18)  # noqa: SIM115
        self.rows: TextIO = open(folder / f"{name}.csv", "w", buffering=1 << 18)  # noqa: SIM115

    def frame(self, t: float, q: Sequence[float]) -> None:
        placement = self.robot.ee_pose(q) * self.tool
        pose = numbers([*placement.translation, *pin.rpy.matrixToRpy(placement.rotation)])
        self.body.write("sleep 0.01\n")
        self.body.write(f"joints {','.join([repr(float(v)) for v in q])}\n")
        self.rows.write(f"{t:.6f},{numbers(q)},{pose}\n")

    def close(self) -> None:
        self.body.close()
        self.rows.close()


class ObjectFrames:
    """The same two messages as rosbags message objects, serialized by rosbags."""

    def __init__(self, arm: BagRobot) -> None:
        self.arm = arm
        self.writer = arm.writer
        self.typestore = arm.writer.typestore
        self.types = self.typestore.types
        arm.writer.write(arm.topic, "sensor_msgs/msg/JointState", 0.0, _empty_state())
        arm.writer.write("/tf", "tf2_msgs/msg/TFMessage", 0.0, {"transforms": []})
        self.js_conn = arm.writer._connections[arm.topic][0]  # noqa: SLF001 (a benchmark)
        self.tf_conn = arm.writer._connections["/tf"][0]  # noqa: SLF001

    def frame(self, t: float, q: Sequence[float]) -> None:
        types, tree, robot = self.types, self.arm.tree, self.arm.robot
        ns = round(t * 1e9)
        full = robot.configuration(q)
        names, positions = tree.joint_positions(full)

        def header(frame: str) -> Any:
            time_ = types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            return types["std_msgs/msg/Header"](stamp=time_, frame_id=frame)

        state = types["sensor_msgs/msg/JointState"](
            header=header(""),
            name=list(names),
            position=np.array(positions),
            velocity=np.empty(0),
            effort=np.empty(0),
        )
        transforms = [
            types["geometry_msgs/msg/TransformStamped"](
                header=header(parent),
                child_frame_id=child,
                transform=types["geometry_msgs/msg/Transform"](
                    translation=types["geometry_msgs/msg/Vector3"](x=xyz[0], y=xyz[1], z=xyz[2]),
                    rotation=types["geometry_msgs/msg/Quaternion"](
                        x=quat[0], y=quat[1], z=quat[2], w=quat[3]
                    ),
                ),
            )
            for parent, child, xyz, quat in tree.moving_transforms(full)
        ]
        tf = types["tf2_msgs/msg/TFMessage"](transforms=transforms)
        raw_writer = self.writer._writer  # noqa: SLF001
        raw_writer.write(
            self.js_conn, ns, self.typestore.serialize_cdr(state, "sensor_msgs/msg/JointState")
        )
        raw_writer.write(
            self.tf_conn, ns, self.typestore.serialize_cdr(tf, "tf2_msgs/msg/TFMessage")
        )


def _empty_state() -> dict[str, Any]:
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
        "name": [],
        "position": [],
        "velocity": [],
        "effort": [],
    }


def cpu_per_frame_us(step: Callable[[float], None], frames: int, reps: int) -> float:
    """Median over ``reps`` runs of the CPU time of one call of ``step`` [us]."""
    runs = []
    t = 0.0
    for _ in range(reps):
        start = time.process_time()
        for _ in range(frames):
            t += 1 / RATE_HZ
            step(t)
        runs.append((time.process_time() - start) / frames * 1e6)
    return statistics.median(runs)


def writing(frames: int, reps: int) -> None:
    robot = load()
    rng = np.random.default_rng(1)
    states = [robot.random(rng) for _ in range(64)]
    print(f"writing one 100 Hz frame, motoman_sia20d ({frames} frames x {reps} runs, CPU time)")
    print(
        f"{'robots':>6s} {'csv us':>8s} {'bag us':>8s} {'objects us':>10s} {'+core':>7s} "
        f"{'bag/csv':>8s}"
    )
    for count in (1, 8):
        with tempfile.TemporaryDirectory() as folder:
            where = Path(folder)
            csvs = [CsvRows(robot, where, f"r{k}") for k in range(count)]
            writer = BagWriter(where / "bag")
            arms = [BagRobot(writer, robot, f"r{k}" if count > 1 else "") for k in range(count)]
            for arm in arms:
                arm.start(0.0)
            other = BagWriter(where / "objects")
            objects = [ObjectFrames(BagRobot(other, robot, f"r{k}")) for k in range(count)]

            def each(items: Sequence[Any]) -> Callable[[float], None]:
                def step(t: float) -> None:
                    q = states[int(t * RATE_HZ) % len(states)]
                    for item in items:
                        item.frame(t, q)

                return step

            csv_us = cpu_per_frame_us(each(csvs), frames, reps)
            bag_us = cpu_per_frame_us(each(arms), frames, reps)
            objects_us = cpu_per_frame_us(each(objects), frames, reps)
            for item in csvs:
                item.close()
            writer.close()
            other.close()
        core = bag_us * RATE_HZ / 1e6 * 100
        print(
            f"{count:6d} {csv_us:8.1f} {bag_us:8.1f} {objects_us:10.1f} {core:6.2f}% "
            f"{bag_us / csv_us:7.2f}x"
        )
    print("goal: the bag adds <= 10 % CPU at 100 Hz ('+core': the share of one core it adds)")


def long_bag(path: Path, minutes: float) -> Path:
    """A c2rviz-like recording of ``minutes`` at 100 Hz (joint states and TF)."""
    robot = load()
    rng = np.random.default_rng(3)
    start = time.perf_counter()
    with BagWriter(path) as writer:
        arm = BagRobot(writer, robot)
        arm.start(0.0)
        q = np.array(robot.home)
        for i in range(round(minutes * 60 * RATE_HZ)):
            q = np.clip(q + rng.normal(0, 0.002, robot.n), robot.lower, robot.upper)
            arm.frame(i / RATE_HZ, q.tolist())
    size = sum(p.stat().st_size for p in path.iterdir()) / 1e6
    print(f"wrote {path.name}: {minutes:g} min at 100 Hz, {size:.0f} MB, in "
          f"{time.perf_counter() - start:.1f} s")  # fmt: skip
    return path


def chain_names() -> tuple[str, ...]:
    """The motoman's chain (all its moving joints), without loading Pinocchio."""
    root = ET.fromstring(URDF.read_text())
    return tuple(j.get("name", "") for j in root.iter("joint") if j.get("type") != "fixed")


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def long_ros1_bag(path: Path, minutes: float) -> Path:
    """The same joint states as a ROS 1 bag (rosbags' rosbag1 writer), for comparison."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types, msgtype = store.types, "sensor_msgs/msg/JointState"
    names = list(chain_names())
    rng = np.random.default_rng(3)
    q = np.zeros(len(names))
    with Writer1(path) as writer:
        conn = writer.add_connection("/joint_states", msgtype, typestore=store)
        for i in range(round(minutes * 60 * RATE_HZ)):
            q = q + rng.normal(0, 0.002, len(names))
            ns = i * 10_000_000
            time_ = types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
            message = types[msgtype](
                header=types["std_msgs/msg/Header"](seq=i, stamp=time_, frame_id=""),
                name=names,
                position=q,
                velocity=np.empty(0),
                effort=np.empty(0),
            )
            writer.write(conn, ns, store.serialize_ros1(message, msgtype))
    print(f"wrote {path.name}: {minutes:g} min at 100 Hz, {path.stat().st_size / 1e6:.0f} MB")
    return path


def read_once(path: Path, duration_s: float | None) -> dict[str, float]:
    """In this process: open, check the span, time to the first sample, then the rest."""
    chain = chain_names()
    start = time.perf_counter()
    bag = JointStateBag.open(path)
    opened = time.perf_counter()
    rss_open = peak_rss_mb()
    warnings = bag.check(chain, 0.0, duration_s)
    checked = time.perf_counter()
    samples = bag.samples(chain, 0.0, duration_s)
    next(samples)
    first = time.perf_counter()
    count = 1 + sum(1 for _ in samples)
    done = time.perf_counter()
    bag.close()
    return {
        "open_s": opened - start,
        "check_s": checked - opened,
        "first_s": first - start,
        "all_s": done - start,
        "samples": count,
        "warnings": len(warnings),
        "open_rss_mb": rss_open,
        "peak_rss_mb": peak_rss_mb(),
    }


def reading(path: Path) -> None:
    print(f"reading {path.name} as the player will (a fresh process each; wall time)")
    print(f"{'span':>8s} {'open s':>7s} {'check s':>8s} {'first s':>8s} {'goal':>5s} "
          f"{'all s':>7s} {'samples':>8s} {'RSS open':>9s} {'peak RSS':>9s}")  # fmt: skip
    for label, duration, goal in (("60 s", "60", 2.0), ("whole", "none", 10.0)):
        done = subprocess.run(
            [sys.executable, __file__, "--read-child", str(path), duration],
            capture_output=True,
            text=True,
            check=True,
        )
        r = json.loads(done.stdout.strip().splitlines()[-1])
        print(
            f"{label:>8s} {r['open_s']:7.2f} {r['check_s']:8.2f} {r['first_s']:8.2f} "
            f"{goal:4.0f}s {r['all_s']:7.2f} {r['samples']:8d} {r['open_rss_mb']:6.0f} MB "
            f"{r['peak_rss_mb']:6.0f} MB"
        )
    print("goals: first sample <= 2 s (60 s span) and <= 10 s (whole), check included; "
          "memory flat: 'whole' peaks where '60 s' does, a few MB over the opened bag")  # fmt: skip


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer frames; a 6-minute bag")
    parser.add_argument("--minutes", type=float, help="length of the bag to read (default 60)")
    parser.add_argument("--keep", type=Path, help="write the long bag in this folder and keep it")
    parser.add_argument("--ros1", action="store_true", help="also read a ROS 1 .bag as long")
    parser.add_argument("--read-child", nargs=2, metavar=("BAG", "SECONDS"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.read_child:
        path, seconds = args.read_child
        print(json.dumps(read_once(Path(path), None if seconds == "none" else float(seconds))))
        return 0
    writing(frames=500 if args.quick else 3000, reps=3 if args.quick else 7)
    print()
    minutes = args.minutes or (6.0 if args.quick else 60.0)
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        if args.keep is not None:
            args.keep.mkdir(parents=True, exist_ok=True)
            folder = args.keep
        path = folder / f"joint_states_{minutes:g}min"
        reading(path if path.exists() else long_bag(path, minutes))
        if args.ros1:
            print()
            ros1 = folder / f"joint_states_{minutes:g}min.bag"
            reading(ros1 if ros1.exists() else long_ros1_bag(ros1, minutes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
