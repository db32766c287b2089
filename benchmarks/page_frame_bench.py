"""What one frame to the page process costs the command process (``--page-process``).

Usage: ``python benchmarks/page_frame_bench.py [--frames 2000]``.

The command process's share of the page is ``page_frame.FrameNotes.frame`` (the message
made of what changed) and ``page_channel.encode`` (its msgpack bytes); the socket write
after it is the same one call whatever the frame holds. This times both, in one process,
for 1, 8 and 64 robots each with a new joint sample per frame, then for one robot
carrying a part among 20 (every frame then carries the parts' rows) with 4 cameras
(whose rows go only when they change). Printed: the median and 99th percentile [us] per
frame and the frame's size, beside the issue's bound (issue 40: a bounded, measured time
per frame, whatever the number of tabs: there is no tab here, as there is none in the
command process).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Sequence
from pathlib import Path

import pinocchio as pin

from c2rviz.robot.model import Robot
from c2rviz.session.services import Services
from c2rviz.session.session import Session
from c2rviz.view.page_channel import encode
from c2rviz.view.page_frame import FrameNotes
from c2rviz.world.cameras import Camera
from c2rviz.world.world import World

ROOT = Path(__file__).resolve().parent.parent


def world_of(robots: int) -> tuple[World, Services, FrameNotes]:
    robot = Robot.from_urdf(ROOT / "robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
    world = World({f"r{k}": robot for k in range(robots)})
    services = Services(world)
    sessions = {name: Session(services, source="page", robot=name) for name in world.robots}
    notes = FrameNotes(services, sessions, 8)
    world.add_observers([notes])
    notes.fresh()
    return world, services, notes


def timed(world: World, notes: FrameNotes, frames: int, carry: bool) -> tuple[list[float], int]:
    """Each frame: every robot moves (a sample), then the frame is made and encoded."""
    costs: list[float] = []
    size = 0
    names = list(world.robots)
    for k in range(frames):
        q = [0.001 * (k % 1000)] + [0.0] * 6
        for name in names:
            world._show(world.robots[name], tuple(q), world.clock.now())
        if carry:
            world.parts.changed(models=False)  # what a held part's move tells
        began = time.perf_counter()
        data = encode(notes.frame())
        costs.append((time.perf_counter() - began) * 1e6)
        size = len(data)
    return costs, size


def row(what: str, costs: Sequence[float], size: int) -> str:
    ordered = sorted(costs)
    p99 = ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]
    return f"{what:<38} {statistics.median(costs):>8.1f} {p99:>8.1f} {size:>9}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=2000, help="frames timed per case")
    args = parser.parse_args(argv)
    print(f"{'one frame, the command process':<38} {'p50 [us]':>8} {'p99 [us]':>8} {'bytes':>9}")
    for robots in (1, 8, 64):
        world, services, notes = world_of(robots)
        costs, size = timed(world, notes, args.frames, carry=False)
        print(row(f"{robots} robot(s) moving", costs, size), flush=True)
        services.close()
    world, services, notes = world_of(1)
    for k in range(20):
        pose = pin.SE3(pin.SE3.Identity().rotation, pin.SE3.Identity().translation)
        pose.translation[:] = [0.4 + 0.05 * (k % 5), 0.3 + 0.05 * (k // 5), 0.015]
        world.parts.add(f"p{k}", "box", (0.03, 0.03, 0.03), pose)
    for k in range(4):
        world.cameras.put(Camera(f"c{k}", pin.SE3.Identity()))
    costs, size = timed(world, notes, args.frames, carry=True)
    print(row("1 robot moving, 20 parts, 4 cameras", costs, size), flush=True)
    services.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
