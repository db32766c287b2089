"""How does the rosbridge server keep up with a 100 Hz topic and many subscribers?

Usage: ``python benchmarks/rosbridge_bench.py [--quick] [--seconds S] [--counts 1,10,50]``.

This process runs ``RosbridgeServer`` on 127.0.0.1:0 in front of an in-bench
bridge whose ticker delivers a ``sensor_msgs/msg/JointState`` (7 joints,
``header.stamp`` = the monotonic time of delivery) 100 times a second. For each
subscriber count, a second process opens that many raw websockets clients
(``websockets`` asyncio), each subscribing to ``/joint_states``, and notes
when each frame arrives. Over the measured window it prints:

- lag from ``deliver`` to the frame leaving (written to the socket; the
  server's ``sent_probe``) and to it arriving in the client process, p50/p99 [ms];
- the server process's CPU [% of one core], and per subscriber above the
  ticker alone (0 subscribers);
- messages thinned (latest wins) and frames sent per second.

Goal (issue 26): lag to the frame leaving, p99 <= 10 ms at 50 subscribers.
The arriving lag adds the client process's own time (50 Python websockets
clients reading 5000 frames/s share one process), so it is the instrument's
limit as much as the server's. Figures only: nothing here passes or fails. The
machine is shared; its load average is printed first.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import re
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # this checkout's c2rviz

from report import machine  # noqa: E402

from c2rviz.transports.rosbridge import RosbridgePolicy, RosbridgeServer  # noqa: E402

RATE_HZ = 100.0
JOINTS = [f"joint_{i}" for i in range(1, 8)]
GOAL_P99_MS = 10.0
STAMP = re.compile(r'"stamp":\{"sec":(\d+),"nanosec":(\d+)\}')


class BenchBridge:
    """Publishes ``/joint_states`` from a 100 Hz ticker; takes nothing."""

    def __init__(self) -> None:
        self.deliveries: dict[object, Callable[[dict[str, Any]], None]] = {}
        self.ticks = 0

    def topics(self) -> list[tuple[str, str]]:
        return [("/joint_states", "sensor_msgs/msg/JointState")]

    def services(self) -> list[tuple[str, str]]:
        return []

    def params(self) -> dict[str, object]:
        return {}

    def subscribe(self, topic: str, deliver: Callable[[dict[str, Any]], None]) -> object:
        handle = object()
        self.deliveries[handle] = deliver
        return handle

    def unsubscribe(self, handle: object) -> None:
        self.deliveries.pop(handle, None)

    async def publish(self, source: str, topic: str, msg: dict[str, Any]) -> None:
        raise NotImplementedError

    async def call_service(self, source: str, service: str, args: dict[str, Any]) -> dict[str, Any]:
        raise NotImplementedError

    def tick(self) -> None:
        now = time.monotonic()
        sec = int(now)
        angle = 0.001 * self.ticks
        msg = {
            "header": {"stamp": {"sec": sec, "nanosec": int((now - sec) * 1e9)}, "frame_id": ""},
            "name": JOINTS,
            "position": [angle + 0.1 * i for i in range(len(JOINTS))],
            "velocity": [],
            "effort": [],
        }
        self.ticks += 1
        for deliver in list(self.deliveries.values()):
            deliver(msg)

    async def run(self) -> None:
        loop = asyncio.get_running_loop()
        next_t = loop.time()
        while True:
            next_t += 1.0 / RATE_HZ
            await asyncio.sleep(max(0.0, next_t - loop.time()))
            self.tick()


async def clients(url: str, count: int) -> None:
    """The client process: ``count`` subscribers; on 'stop' on stdin, print (stamp, lag) pairs."""
    from websockets.asyncio.client import connect

    lags: list[tuple[float, float]] = []

    async def one() -> None:
        async with connect(url, compression=None, max_size=None) as ws:
            subscribe = {"op": "subscribe", "id": "bench", "topic": "/joint_states"}
            await ws.send(json.dumps(subscribe | {"type": "sensor_msgs/msg/JointState"}))
            async for frame in ws:
                arrived = time.monotonic()
                stamp = STAMP.search(frame)  # cheaper than json.loads: the client is the bottleneck
                assert stamp is not None, frame
                sent = int(stamp[1]) + int(stamp[2]) * 1e-9
                lags.append((sent, arrived - sent))

    tasks = [asyncio.create_task(one()) for _ in range(count)]
    await asyncio.get_running_loop().run_in_executor(None, sys.stdin.readline)
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
    print(json.dumps(lags))


def percentile(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


async def measure(
    server: RosbridgeServer, bridge: BenchBridge, url: str, count: int, seconds: float
) -> dict[str, float]:
    leaving: list[tuple[float, float]] = []
    server.sent_probe = lambda delivered: leaving.append((delivered, time.monotonic() - delivered))
    process = None
    if count:
        process = await asyncio.create_subprocess_exec(
            sys.executable, __file__, "--client-of", url, "--subscribers", str(count),
            stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
        )  # fmt: skip
        deadline = time.monotonic() + 60
        while len(bridge.deliveries) < count:  # a benchmark may poll: it waits for its clients
            if time.monotonic() > deadline:
                raise RuntimeError(f"only {len(bridge.deliveries)} of {count} subscribed")
            await asyncio.sleep(0.05)
    await asyncio.sleep(0.5)  # warm up
    thinned0, sent0, ticks0 = server.stats["thinned"], server.stats["sent"], bridge.ticks
    start, cpu0 = time.monotonic(), time.process_time()
    await asyncio.sleep(seconds)
    end, cpu1 = time.monotonic(), time.process_time()
    figures = {
        "cpu_pct": 100 * (cpu1 - cpu0) / (end - start),
        "thinned": server.stats["thinned"] - thinned0,
        "sent_per_s": (server.stats["sent"] - sent0) / (end - start),
        "rate_hz": (bridge.ticks - ticks0) / (end - start),
    }
    leave = [1000 * lag for t, lag in leaving if start <= t <= end]
    figures |= {"leave_p50": percentile(leave, 0.5), "leave_p99": percentile(leave, 0.99)}
    arrive: list[float] = []
    if process is not None:
        assert process.stdin is not None
        process.stdin.write(b"stop\n")
        await process.stdin.drain()
        out, _ = await process.communicate()
        arrive = [1000 * lag for t, lag in json.loads(out) if start <= t <= end]
    figures |= {"arrive_p50": percentile(arrive, 0.5), "arrive_p99": percentile(arrive, 0.99)}
    server.sent_probe = None
    return figures


async def bench(counts: Sequence[int], seconds: float) -> list[tuple[int, dict[str, float]]]:
    bridge = BenchBridge()
    server = RosbridgeServer(bridge, RosbridgePolicy(max_connections=max(counts) + 1))
    host, port = await server.start("127.0.0.1", 0)
    ticker = asyncio.create_task(bridge.run())
    try:
        results = [(0, await measure(server, bridge, "", 0, seconds))]
        for count in counts:
            results.append(
                (count, await measure(server, bridge, f"ws://{host}:{port}/", count, seconds))
            )
    finally:
        ticker.cancel()
        await asyncio.gather(ticker, return_exceptions=True)
        await server.stop()
    return results


def table(results: list[tuple[int, dict[str, float]]]) -> str:
    head = (
        "| subscribers | ticks/s | frames/s | thinned | server CPU % | CPU %/subscriber "
        "| leave p50 ms | leave p99 ms | arrive p50 ms | arrive p99 ms | goal: leave p99 <= 10 ms |"
    )
    rows = [head, "|" + "---|" * (head.count("|") - 1)]
    idle = results[0][1]["cpu_pct"]
    for count, f in results:
        per = f"{(f['cpu_pct'] - idle) / count:.2f}" if count else "-"
        met = "-" if not count else ("yes" if f["leave_p99"] <= GOAL_P99_MS else "no")
        rows.append(
            f"| {count} | {f['rate_hz']:.1f} | {f['sent_per_s']:.0f} | {f['thinned']:.0f} "
            f"| {f['cpu_pct']:.1f} | {per} | {f['leave_p50']:.2f} | {f['leave_p99']:.2f} "
            f"| {f['arrive_p50']:.2f} | {f['arrive_p99']:.2f} | {met} |"
        )
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="2 s per count instead of 10")
    parser.add_argument("--seconds", type=float, help="measured window per count [s]")
    parser.add_argument("--counts", default="1,10,50", help="subscriber counts (comma-separated)")
    parser.add_argument("--client-of", help=argparse.SUPPRESS)
    parser.add_argument("--subscribers", type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.client_of:
        asyncio.run(clients(args.client_of, args.subscribers))
        return 0
    seconds = args.seconds or (2.0 if args.quick else 10.0)
    counts = [int(c) for c in args.counts.split(",")]
    print(machine())
    print(f"rosbridge: /joint_states at {RATE_HZ:.0f} Hz, {seconds:.0f} s per count")
    print(table(asyncio.run(bench(counts, seconds))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
