"""How does the real c2rviz server's rosbridge door keep up with /joint_states at 100 Hz?

Usage: ``python benchmarks/rosbridge_bench.py [--quick] [--seconds S] [--counts 1,10,50]``.

Three processes:

- the server (this script with ``--serve``): c2rviz wired as the program wires
  it (a ``World`` with motoman_sia20d, its ``Services``, the text port and the
  app's rosbridge door), its connection cap raised to 64 for the 50 subscribers;
  it notes, for each ``/joint_states`` frame written, the time from the world's
  change (the message's stamp: the world's clock, this machine's monotonic
  clock) to the frame leaving (the websocket write returning: the server's
  ``sent_probe``, paired with the message delivered at that time), and its own CPU;
- the subscribers (``--client-of``, run under ``nice -n 10`` so that this
  instrument yields the CPU to what it measures): N raw websockets clients each
  subscribed to ``/joint_states``, noting when each frame arrives;
- this process, the driver: a text-port client that sends ``joints ...`` 100
  times a second (each a new pose: the world changes at 100 Hz) and times each
  reply, so the text port's request/reply is measured while rosbridge serves.

For 0 subscribers (the idle row) and each count it prints: messages published
per second, frames sent, messages thinned (latest wins), the server's CPU [% of
one core] and per subscriber above idle, lag from the world's change to the
frame leaving and to it arriving in the subscribers' process (p50/p99 [ms];
50 Python clients reading 5000 frames/s share one process, so arriving lag is the
instrument's limit as much as the server's), and the text port's request/reply
p50/p99 [ms] with its p99 beside the idle row's.

Goals (issue 26): leave p99 <= 10 ms at 50 subscribers; the text port's
request/reply p99 within 1.5x of idle. Figures only: nothing here passes or
fails. The machine is shared; its load average is printed first.
"""

from __future__ import annotations

import argparse
import asyncio
import bisect
import json
import math
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this checkout's c2rviz

from report import machine  # noqa: E402

RATE_HZ = 100.0
GOAL_LEAVE_P99_MS = 10.0
GOAL_RTT_RATIO = 1.5
MAX_CONNECTIONS = 64
STAMP = re.compile(r'"stamp":\{"sec":(-?\d+),"nanosec":(\d+)\}')


def percentile(values: Sequence[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


# The server process.


async def serve() -> None:
    """c2rviz as the program wires it; stdin: ``start`` / ``stop`` (figures) / ``quit``."""
    from c2rviz.app.config import Settings
    from c2rviz.app.doors import RosbridgeDoor
    from c2rviz.robot.model import Robot
    from c2rviz.session import Services
    from c2rviz.transports.rosbridge import RosbridgePolicy
    from c2rviz.transports.tcp_server import CommandServer
    from c2rviz.world.world import World

    robot = Robot.from_urdf(ROOT / "robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
    world = World(robot, hz=RATE_HZ)
    services = Services(world)
    text = CommandServer(services)
    _, text_port = await text.start("127.0.0.1", 0)
    door = RosbridgeDoor(services, Settings(), lambda: None)
    door.server.policy = RosbridgePolicy(max_connections=MAX_CONNECTIONS)
    await door.start("127.0.0.1", 0)
    server, hub = door.server, door.bridge.hub
    leaving: list[float] = []
    published: list[tuple[float, float]] = []  # (when handed to the subscribers, stamp) [s]
    measuring = [False]

    def probe(delivered: float) -> None:
        """A frame left: pair its delivery with the /joint_states message delivered then."""
        if measuring[0] and published:
            k = bisect.bisect_right(published, (delivered, math.inf)) - 1
            if k >= 0:
                leaving.append(time.monotonic() - published[k][1])

    original = hub.publish

    def noting(topic: str, msg: dict[str, Any]) -> None:
        if topic == "/joint_states" and measuring[0]:
            stamp = msg["header"]["stamp"]
            published.append((time.monotonic(), stamp["sec"] + stamp["nanosec"] * 1e-9))
        original(topic, msg)  # each outbox notes its delivery time, after ours

    hub.publish = noting  # type: ignore[method-assign]
    server.sent_probe = probe  # outboxes take it when made: set before anyone subscribes
    print(f"ports {text_port} {door.port}", flush=True)
    loop = asyncio.get_running_loop()
    started = (0.0, 0.0, 0, 0, 0)
    while True:
        command = (await loop.run_in_executor(None, sys.stdin.readline)).strip()
        if command == "start":
            leaving.clear()
            published.clear()
            measuring[0] = True
            stats = server.stats
            started = (time.monotonic(), time.process_time(), stats["sent"], stats["thinned"], 0)
        elif command == "stop":
            wall, cpu = time.monotonic() - started[0], time.process_time() - started[1]
            measuring[0] = False
            lags = [1000 * lag for lag in leaving]
            figures = {
                "cpu_pct": 100 * cpu / wall,
                "published_per_s": len(published) / wall,
                "sent_per_s": (server.stats["sent"] - started[2]) / wall,
                "thinned": server.stats["thinned"] - started[3],
                "leave_p50": percentile(lags, 0.5),
                "leave_p99": percentile(lags, 0.99),
                "subscribers": hub.count("/joint_states"),
            }
            print(json.dumps(figures), flush=True)
        else:
            break
    await door.stop()
    await text.stop()
    services.close()


# The subscribers' process.


async def clients(url: str, count: int) -> None:
    """``count`` subscribers; 'ready' once each has its first frame; on 'stop', the lags."""
    from websockets.asyncio.client import connect

    lags: list[tuple[float, float]] = []
    ready = asyncio.Event()
    waiting = [count]

    async def one() -> None:
        async with connect(url, compression=None, max_size=None) as ws:
            subscribe = {"op": "subscribe", "id": "bench", "topic": "/joint_states"}
            await ws.send(json.dumps(subscribe | {"type": "sensor_msgs/msg/JointState"}))
            first = True
            async for frame in ws:
                arrived = time.monotonic()
                if first:  # the greeting: where the arm was when it subscribed
                    first = False
                    waiting[0] -= 1
                    if not waiting[0]:
                        ready.set()
                    continue
                stamp = STAMP.search(frame)  # cheaper than json.loads: the client is the bottleneck
                assert stamp is not None, frame
                sent = int(stamp[1]) + int(stamp[2]) * 1e-9
                lags.append((sent, arrived - sent))

    tasks = [asyncio.create_task(one()) for _ in range(count)]
    await ready.wait()
    print("ready", flush=True)
    await asyncio.get_running_loop().run_in_executor(None, sys.stdin.readline)
    for task in tasks:
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)
    print(json.dumps(lags), flush=True)


# The driver (this process).


async def drive(port: int, stop: asyncio.Event, rtts: list[tuple[float, float]]) -> None:
    """``joints`` at 100 Hz on the text port, each a new pose; (sent time, round trip [s])."""
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    loop = asyncio.get_running_loop()
    next_t, k = loop.time(), 0
    try:
        while not stop.is_set():
            k += 1
            angle = 0.3 * ((k % 200) / 100 - 1)
            sent = time.monotonic()
            writer.write(f"joints {angle:.4f},0.1,0.2,0.3,0.4,0.5,{-angle:.4f}\n".encode())
            line = await reader.readline()
            assert line == b"ok\n", line
            rtts.append((sent, time.monotonic() - sent))
            next_t += 1 / RATE_HZ
            await asyncio.sleep(max(0.0, next_t - loop.time()))
    finally:
        writer.close()
        await writer.wait_closed()


async def measure(
    server: asyncio.subprocess.Process, ports: tuple[int, int], count: int, seconds: float
) -> dict[str, float]:
    assert server.stdin is not None and server.stdout is not None
    subscribers = None
    if count:
        subscribers = await asyncio.create_subprocess_exec(
            "nice", "-n", "10",  # the instrument yields the CPU to the server and the driver
            sys.executable, __file__, "--client-of", f"ws://127.0.0.1:{ports[1]}/",
            "--subscribers", str(count),
            stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
        )  # fmt: skip
        assert subscribers.stdout is not None
        line = await asyncio.wait_for(subscribers.stdout.readline(), 120)
        assert line == b"ready\n", line
    stop, rtts = asyncio.Event(), []
    driver = asyncio.create_task(drive(ports[0], stop, rtts))
    await asyncio.sleep(0.5)  # warm up
    server.stdin.write(b"start\n")
    await server.stdin.drain()
    start = time.monotonic()
    await asyncio.sleep(seconds)
    end = time.monotonic()
    server.stdin.write(b"stop\n")
    await server.stdin.drain()
    figures = json.loads(await server.stdout.readline())
    stop.set()
    await driver
    window = [1000 * rtt for t, rtt in rtts if start <= t <= end]
    figures |= {"rtt_p50": percentile(window, 0.5), "rtt_p99": percentile(window, 0.99)}
    arrive: list[float] = []
    if subscribers is not None:
        assert subscribers.stdin is not None
        subscribers.stdin.write(b"stop\n")
        await subscribers.stdin.drain()
        out, _ = await subscribers.communicate()
        arrive = [1000 * lag for t, lag in json.loads(out) if start <= t <= end]
    figures |= {"arrive_p50": percentile(arrive, 0.5), "arrive_p99": percentile(arrive, 0.99)}
    return figures


async def bench(counts: Sequence[int], seconds: float) -> list[tuple[int, dict[str, float]]]:
    server = await asyncio.create_subprocess_exec(
        sys.executable, __file__, "--serve",
        stdin=asyncio.subprocess.PIPE, stdout=asyncio.subprocess.PIPE,
    )  # fmt: skip
    assert server.stdin is not None and server.stdout is not None
    try:
        words = (await asyncio.wait_for(server.stdout.readline(), 120)).split()
        assert words[:1] == [b"ports"], words
        ports = (int(words[1]), int(words[2]))
        results = [(0, await measure(server, ports, 0, seconds))]
        for count in counts:
            results.append((count, await measure(server, ports, count, seconds)))
    finally:
        if server.returncode is None:
            server.stdin.write(b"quit\n")
            await server.stdin.drain()
            await asyncio.wait_for(server.wait(), 60)
    return results


def table(results: list[tuple[int, dict[str, float]]]) -> str:
    head = (
        "| subscribers | msgs/s | frames/s | thinned | server CPU % | CPU %/subscriber "
        "| leave p50 ms | leave p99 ms | arrive p50 ms | arrive p99 ms "
        "| text p50 ms | text p99 ms | text p99 / idle | goal: leave p99 <= 10 ms "
        "| goal: text p99 <= 1.5x idle |"
    )
    rows = [head, "|" + "---|" * (head.count("|") - 1)]
    idle = results[0][1]
    for count, f in results:
        per = f"{(f['cpu_pct'] - idle['cpu_pct']) / count:.2f}" if count else "-"
        ratio = f["rtt_p99"] / idle["rtt_p99"]
        leave_met = "-" if not count else ("yes" if f["leave_p99"] <= GOAL_LEAVE_P99_MS else "no")
        rtt_met = "-" if not count else ("yes" if ratio <= GOAL_RTT_RATIO else "no")
        rows.append(
            f"| {count} | {f['published_per_s']:.1f} | {f['sent_per_s']:.0f} | {f['thinned']:.0f} "
            f"| {f['cpu_pct']:.1f} | {per} | {f['leave_p50']:.2f} | {f['leave_p99']:.2f} "
            f"| {f['arrive_p50']:.2f} | {f['arrive_p99']:.2f} | {f['rtt_p50']:.2f} "
            f"| {f['rtt_p99']:.2f} | {ratio:.2f} | {leave_met} | {rtt_met} |"
        )
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="1 s per count instead of 10")
    parser.add_argument("--seconds", type=float, help="measured window per count [s]")
    parser.add_argument("--counts", default="1,10,50", help="subscriber counts (comma-separated)")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--client-of", help=argparse.SUPPRESS)
    parser.add_argument("--subscribers", type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.serve:
        asyncio.run(serve())
        return 0
    if args.client_of:
        asyncio.run(clients(args.client_of, args.subscribers))
        return 0
    seconds = args.seconds or (1.0 if args.quick else 10.0)
    counts = [int(c) for c in args.counts.split(",")]
    print(machine())
    print(
        f"rosbridge: /joint_states of a real c2rviz server, the world changed {RATE_HZ:.0f} "
        f"times a second by text-port `joints` lines; {seconds:g} s per count"
    )
    print(table(asyncio.run(bench(counts, seconds))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
