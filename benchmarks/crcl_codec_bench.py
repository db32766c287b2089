"""What the CRCL codec costs per document: parse a command, write a status, split a stream.

Each row times one call many times and prints the wall-clock median and 99th
percentile and the 99th percentile of the CPU (thread) time [us] beside the goal of
issue 24 (parse and write <= 200 us each). The goal is judged on the CPU p99: on a
shared machine the wall p99 also counts the time other processes held the core.

The MoveTo is written as NIST's tools write it (declaration, indented); the full
status has 7 joints (position and velocity), the pose, a parallel gripper and
settings (units, speeds, tolerances); the compact one is what a server pushes
(CommandStatus and PoseStatus). The last rows split a 1 MiB document fed in 64 KiB
and in 1 KiB chunks: near rates mean the splitter is linear in the bytes fed (a
quadratic one would be ~64 times slower in 1 KiB chunks).

Run: ``python benchmarks/crcl_codec_bench.py [--quick]``.
"""

from __future__ import annotations

import argparse
import gc
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.transports.crcl import (  # noqa: E402
    CommandStatus,
    CrclStatus,
    DocumentSplitter,
    JointStatus,
    JointStatuses,
    ParallelGripperStatus,
    Point,
    Pose,
    PoseStatus,
    PoseTolerance,
    RotSpeedRelative,
    SettingsStatus,
    TransAccelAbsolute,
    TransSpeedAbsolute,
    Vector,
    parse_command,
    write_status,
)

__all__ = ["main"]

GOAL_US = 200.0
MOVE_TO = b"""<?xml version="1.0" encoding="UTF-8"?>
<CRCLCommandInstance
  xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <CRCLCommand xsi:type="MoveToType">
    <CommandID>2</CommandID>
    <MoveStraight>false</MoveStraight>
    <EndPosition>
      <Point>
        <X>0.4653</X> <Y>-0.1221</Y> <Z>0.3875</Z>
      </Point>
      <XAxis>
        <I>0.7071067811865476</I> <J>0.7071067811865475</J> <K>0</K>
      </XAxis>
      <ZAxis>
        <I>0</I> <J>0</J> <K>-1</K>
      </ZAxis>
    </EndPosition>
  </CRCLCommand>
</CRCLCommandInstance>
"""
GET_STATUS = (
    b'<?xml version="1.0" encoding="UTF-8"?><CRCLCommandInstance xmlns:xsi="http://www.w3.org/'
    b'2001/XMLSchema-instance"><CRCLCommand xsi:type="GetStatusType"><CommandID>3</CommandID>'
    b"</CRCLCommand></CRCLCommandInstance>"
)
POSE = Pose(
    Point(0.46530000000000005, -0.12209999999999999, 0.38749999999999996),
    Vector(0.7071067811865476, 0.7071067811865475, 1.2246467991473532e-16),
    Vector(-8.659560562354934e-17, 8.659560562354932e-17, -1.0),
)
COMMAND = CommandStatus(command_id=2, status_id=1234, state="CRCL_Working")
FULL = CrclStatus(
    command_status=COMMAND,
    joint_statuses=JointStatuses(
        tuple(
            JointStatus(joint_number=n, position=0.123456789 * n, velocity=-0.0123456789 * n)
            for n in range(1, 8)
        )
    ),
    pose_status=PoseStatus(pose=POSE),
    gripper_status=ParallelGripperStatus(gripper_name="panda_hand", separation=0.0795),
    settings_status=SettingsStatus(
        angle_unit="radian",
        end_effector_setting=1.0,
        length_unit="meter",
        motion_coordinated=True,
        end_pose_tolerance=PoseTolerance(0.001, 0.001, 0.001, 0.01, 0.01),
        rot_speed_relative=RotSpeedRelative(0.5),
        trans_accel_absolute=TransAccelAbsolute(2.0),
        trans_speed_absolute=TransSpeedAbsolute(0.25),
    ),
)
COMPACT = CrclStatus(command_status=COMMAND, pose_status=PoseStatus(pose=POSE))


def machine() -> str:
    """One line naming the machine and its load, printed first."""
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
        f"{platform.system()} {platform.release()}; Python {platform.python_version()}; "
        f"load average {load}"
    )


def per_call_us(call: Callable[[], object], count: int) -> tuple[list[float], list[float]]:
    """The wall and the CPU (thread) time of each of ``count`` calls [us], after a warm-up."""
    for _ in range(min(count, 200)):
        call()
    walls, cpus = [], []
    gc.disable()
    try:
        for _ in range(count):
            wall, cpu = time.perf_counter_ns(), time.thread_time_ns()
            call()
            cpus.append((time.thread_time_ns() - cpu) / 1000.0)
            walls.append((time.perf_counter_ns() - wall) / 1000.0)
    finally:
        gc.enable()
    return walls, cpus


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def split_rate(chunk: int, repeats: int) -> float:
    """MB/s splitting a 1 MiB document fed in ``chunk``-byte pieces."""
    body = b"x" * ((1 << 20) - 200)
    doc = b"<CRCLStatus><Message>" + body + b"</Message></CRCLStatus>"
    best = float("inf")
    for _ in range(repeats):
        splitter = DocumentSplitter(max_bytes=2 << 20)
        start = time.perf_counter()
        out = [
            item for i in range(0, len(doc), chunk) for item in splitter.feed(doc[i : i + chunk])
        ]
        best = min(best, time.perf_counter() - start)
        assert out == [doc]
    return len(doc) / best / 1e6


def row(*cells: str) -> str:
    widths = (27, 5, 9, 9, 9, 9, 4)
    return "| " + " | ".join(f"{cell:>{w}}" if i in (2, 3, 4) else f"{cell:<{w}}"
                             for i, (cell, w) in enumerate(zip(cells, widths))) + " |"  # fmt: skip


def main(argv: Sequence[str] | None = None) -> int:
    """Print the table; returns 0 (the goals are reported, not enforced)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer calls (a smoke run)")
    args = parser.parse_args(argv)
    count = 500 if args.quick else 20_000
    splitter = DocumentSplitter()
    timed: list[tuple[str, Callable[[], object], float | None]] = [
        ("parse MoveTo", lambda: parse_command(MOVE_TO), GOAL_US),
        ("write full status", lambda: write_status(FULL), GOAL_US),
        ("parse GetStatus", lambda: parse_command(GET_STATUS), None),
        ("write compact status", lambda: write_status(COMPACT), None),
        ("split MoveTo (one feed)", lambda: splitter.feed(MOVE_TO), None),
    ]
    print(machine())
    print(f"calls per row: {count}; full status {len(write_status(FULL))} bytes, compact "
          f"{len(write_status(COMPACT))} bytes, MoveTo {len(MOVE_TO)} bytes")  # fmt: skip
    print(row("row", "unit", "median", "p99", "cpu p99", "goal", "met"))
    print(row(*("-" * w for w in (27, 5, 9, 9, 9, 9, 4))))
    for label, call, goal in timed:
        walls, cpus = per_call_us(call, count)
        cpu_p99 = percentile(cpus, 0.99)
        goal_text = f"<= {goal:.0f} us" if goal else ""
        met = ("yes" if cpu_p99 <= goal else "no") if goal else ""
        print(row(label, "us", f"{statistics.median(walls):.1f}", f"{percentile(walls, 0.99):.1f}",
                  f"{cpu_p99:.1f}", goal_text, met))  # fmt: skip
    repeats = 1 if args.quick else 5
    for chunk in (65536, 1024):
        rate = split_rate(chunk, repeats)
        print(
            row(f"split 1 MiB, {chunk // 1024} KiB chunks", "MB/s", f"{rate:.0f}", "", "", "", "")
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
