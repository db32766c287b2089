"""What one frame to the page process costs the command process, and what drawing it
costs the page process (``--page-process``).

Usage: ``python benchmarks/page_frame_bench.py [--frames 2000] [--page-frames 300]``.

The command process's share of the page is ``page_frame.FrameNotes.frame`` (the message
made of what changed) and ``page_channel.encode`` (its msgpack bytes); the socket write
after it is the same one call whatever the frame holds. This times both, in one process,
for 1, 8 and 64 robots each with a new joint sample per frame, then for one robot
carrying a part among 20 (every frame then carries the parts' rows) with 4 cameras
(whose rows go only when they change). Printed: the median and 99th percentile [us] per
frame and the frame's size, beside the issue's bound (issue 40: a bounded, measured time
per frame, whatever the number of tabs: there is no tab here, as there is none in the
command process).

Then the page process's side (issue 40: the page >= 30 frames/s per robot on the CPU it
shares): a ``PageProcess`` of 64 robots in this process, one websocket tab reading in a
process of its own (``loadgen.ViewerClient``), fed frames as ``many_robots.py``'s cell
makes them (every robot moving between two far targets, a new target every 0.5 s, three
joint samples a frame, 30 frames a second). Printed: the CPU time per frame [ms] of the
page process's loop (applying the frame, then its send) and of viser's thread (encoding
and writing what the send queued), and the messages queued per frame.
"""

from __future__ import annotations

import argparse
import asyncio
import math
import pickle
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import pinocchio as pin

from c2rviz.robot.model import Robot
from c2rviz.session.services import Services, SessionDefaults
from c2rviz.session.session import Session
from c2rviz.view.page_channel import encode
from c2rviz.view.page_frame import FrameNotes
from c2rviz.view.page_link import PageLink
from c2rviz.view.page_process import PageProcess
from c2rviz.view.page_snapshot import Hello, PageConfig, snapshot
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


TAB = """
import asyncio, sys
sys.path.insert(0, sys.argv[2])
import loadgen
asyncio.run(loadgen.ViewerClient(sys.argv[1]).run())
"""
FAR = [[math.radians(v) for v in (90, 45, -30, -30, 0, 60, 0)]]
FAR.append([-v for v in FAR[0]])


class _Discard:
    """Stands in for the channel to the command process (the page's ``applied``)."""

    transport = None

    def is_closing(self) -> bool:
        return False

    def write(self, data: bytes) -> None:
        pass


def moving_frame(names: Sequence[str], k: int) -> list[object]:
    """Frame ``k`` (at 30 a second) of ``many_robots.py``'s cell: each robot on its way
    between the far targets, three samples, a new target every 15 frames."""
    t, rows = k / 30.0, []
    for i, name in enumerate(names):
        leg = (k // 15 + i) % 2
        a, b = FAR[1 - leg], FAR[leg]
        samples = []
        for s in range(3):
            f = ((k % 15) * 3 + s + 1) / 45.0
            samples.append([t - (2 - s) / 90.0, *[x + (y - x) * f for x, y in zip(a, b)]])
        rows.append([name, samples, 0.0, tuple(b), True, 1.5 - (k % 15) / 30.0, 100.0])
    return ["frame", t, rows, []]


def thread_cpu_s(tid: int) -> float:
    with open(f"/proc/self/task/{tid}/schedstat") as stat:
        return int(stat.read().split()[0]) / 1e9


async def page_side(robots: int, frames: int) -> tuple[float, float, float]:
    """The page process's CPU per frame [ms]: its loop's, viser's thread's; messages."""
    world, services, _ = world_of(robots)
    config = PageConfig(
        "127.0.0.1", 0, 100.0, (), None, 4, None, SessionDefaults(motion="follow"), 100, 30, 8
    )
    link = PageLink(services, config)
    hello = Hello(config, snapshot(services, link.sessions, []))
    page = PageProcess(pickle.loads(pickle.dumps(hello)), _Discard())  # type: ignore[arg-type]
    scene, names = page.scene, list(world.robots)
    scene.start(asyncio.get_running_loop())
    url = (scene.url or "").replace("http://", "ws://", 1) + "/"
    tab = subprocess.Popen([sys.executable, "-c", TAB, url, str(ROOT / "benchmarks")])
    try:
        await asyncio.sleep(3.0)  # the tab has the scene
        for k in range(30):  # the ghosts are built at the first move
            page.apply(moving_frame(names, k))
            while scene._send():
                pass
            await asyncio.sleep(1 / 30)
        await asyncio.sleep(1.0)
        others = [t.native_id for t in threading.enumerate() if t is not threading.main_thread()]
        buffer = scene.server._websock_server._broadcast_buffer
        loop0, viser0 = time.thread_time(), sum(map(thread_cpu_s, others))
        sent0 = buffer.message_counter
        for k in range(30, 30 + frames):
            page.apply(moving_frame(names, k))
            while scene._send():
                pass
            await asyncio.sleep(1 / 30)
        await asyncio.sleep(0.5)
        loop_ms = (time.thread_time() - loop0) / frames * 1e3
        viser_ms = (sum(map(thread_cpu_s, others)) - viser0) / frames * 1e3
        return loop_ms, viser_ms, (buffer.message_counter - sent0) / frames
    finally:
        tab.terminate()
        tab.wait()
        scene.stop()
        services.close()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=2000, help="frames timed per case")
    parser.add_argument("--page-frames", type=int, default=300, help="the page's (0: none)")
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
    if args.page_frames:
        loop_ms, viser_ms, messages = asyncio.run(page_side(64, args.page_frames))
        print(f"\none frame of 64 robots moving, the page process ({args.page_frames} frames):")
        total = loop_ms + viser_ms
        print(f"  CPU: its loop {loop_ms:.2f} ms + viser's thread {viser_ms:.2f} ms")
        print(f"  = {total:.2f} ms ({1e3 / total:.0f} frames/s on a core of its own)")
        print(f"  {messages:.0f} messages queued a frame")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
