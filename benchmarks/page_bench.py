"""What the page costs the command server: floods, memory, and the viewer's sends.

Prints, on this machine:

* a bystander's request/reply round trip (``where``, one at a time) while
  another client floods ``mark`` (at the end effector, and at a new place each
  line), against the same while it floods ``where``, and with no flood [ms];
  the program runs as ``python -m c2rviz`` with one reading viewer tab, then
  with ``--no-viewer`` (what is left is the command's own cost);
* the program's resident memory after 20k and 60k marks at new places [MB];
* in this process, on a ``ViserScene``: the command-path cost of a marker
  (``on_marker``) [us], a send after a pose change and after 1000 new markers
  [ms], and, for comparison, what a marker cost as a viser node of its own
  (the viewer before batching) [ms].

Run: ``PYTHONPATH=. python benchmarks/page_bench.py`` (about a minute).
"""

from __future__ import annotations

import asyncio
import socket
import sys
import threading
import time
import timeit
from collections.abc import Sequence
from pathlib import Path

import msgspec
import numpy as np
import viser
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

sys.path.insert(0, str(Path(__file__).resolve().parent))
from processes import launch_ours  # noqa: E402

from c2rviz.robot.model import Robot  # noqa: E402
from c2rviz.session import Services  # noqa: E402
from c2rviz.view import adapter  # noqa: E402
from c2rviz.view.viser_scene import ViserScene  # noqa: E402
from c2rviz.world.observer import Marker  # noqa: E402
from c2rviz.world.world import World  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
CAMERA = {
    "type": "ViewerCameraMessage",
    **{"wxyz": [1.0, 0.0, 0.0, 0.0], "position": [3.0, 0.0, 1.0], "fov": 1.0},
    **{"near": 0.01, "far": 100.0, "image_height": 700, "image_width": 1000},
    **{"look_at": [0.0, 0.0, 0.5], "up_direction": [0.0, 0.0, 1.0]},
}


class ReadingTab:
    """A viewer tab that reads (and drops) everything viser sends, on its own thread."""

    def __init__(self, url: str) -> None:
        self.ws = connect(
            url.replace("http://", "ws://"),
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            max_size=None,
        )
        self.ws.send(msgspec.msgpack.encode(CAMERA))
        self.bytes = 0
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        try:
            while True:
                self.bytes += len(self.ws.recv())
        except (ConnectionClosed, OSError):
            pass

    def close(self) -> None:
        self.ws.close()
        self.thread.join(timeout=10)


class Flood:
    """One client sending ``lines`` over and over, reading its replies, until stopped."""

    def __init__(self, address: tuple[str, int], lines: list[bytes]) -> None:
        self.sock = socket.create_connection(address)
        self.payload = b"".join(lines)
        self.count = len(lines)
        self.sent = self.received = 0
        self.stopped = threading.Event()
        self.threads = [
            threading.Thread(target=self._send, daemon=True),
            threading.Thread(target=self._read, daemon=True),
        ]
        for thread in self.threads:
            thread.start()

    def _send(self) -> None:
        while not self.stopped.is_set():
            self.sock.sendall(self.payload)
            self.sent += self.count

    def _read(self) -> None:
        while not self.stopped.is_set() or self.received < self.sent:
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                return
            self.received += chunk.count(b"\n")

    def stop(self) -> int:
        self.stopped.set()
        self.threads[0].join(timeout=60)
        self.threads[1].join(timeout=60)
        self.sock.close()
        return self.received


def round_trips(address: tuple[str, int], count: int) -> list[float]:
    """``where``, one at a time: every round trip [s] after count // 10 warm-ups."""
    sock = socket.create_connection(address)
    times = []
    try:
        for k in range(count + count // 10):
            start = time.perf_counter()
            sock.sendall(b"where\n")
            reply = sock.recv(256)
            while not reply.endswith(b"\n"):
                reply += sock.recv(256)
            if k >= count // 10:
                times.append(time.perf_counter() - start)
            assert reply.startswith(b"ok "), reply
    finally:
        sock.close()
    return times


def p(times: list[float], q: float) -> float:
    return float(np.percentile(times, q)) * 1e3


def mark_lines(count: int, offset: int = 0) -> list[bytes]:
    """``mark x,y,0.5,0,0,0`` at a new place each line (a 1 mm grid)."""
    places = ((k % 1000 * 1e-3, k // 1000 % 1000 * 1e-3) for k in range(offset, offset + count))
    return [f"mark {x:.3f},{y:.3f},0.5,0,0,0\n".encode() for x, y in places]


def bystander(viewer: bool) -> None:
    shown = "viewer tab open" if viewer else "--no-viewer"
    print(f"bystander 'where' round trip while another client floods [ms] ({shown}):")
    proc = launch_ours(viewer=viewer)
    tab = ReadingTab(proc.url or "") if viewer else None
    floods = {
        "no flood": None,
        "flood of where": [b"where\n"] * 10_000,
        "flood of mark (at the ee)": [b"mark\n"] * 10_000,
        "flood of mark x,y,z,r,p,y": mark_lines(10_000),
    }
    figures = {}
    try:
        for name, lines in floods.items():
            flood = Flood(proc.address, lines) if lines else None
            time.sleep(0.5)
            times = round_trips(proc.address, 2000)
            done = flood.stop() if flood else 0
            figures[name] = p(times, 99)
            print(
                f"  {name:28s} p50 {p(times, 50):7.3f}  p99 {p(times, 99):7.3f}"
                f"  ({done} flood lines answered meanwhile)"
            )
        base = figures["flood of where"]
        for name in ("flood of mark (at the ee)", "flood of mark x,y,z,r,p,y"):
            print(f"  p99 {name} / flood of where: {figures[name] / base:5.2f} (goal <= 2)")
    finally:
        if tab is not None:
            tab.close()
        proc.stop()


def memory() -> None:
    print("program RSS after marks at new places (a viewer tab reading) [MB]:")
    proc = launch_ours(viewer=True)
    tab = ReadingTab(proc.url or "")
    sock = socket.create_connection(proc.address)
    try:
        print(f"  {'at start':10s} {proc.rss_mb():7.1f}")
        sent = 0
        for total in (20_000, 40_000, 60_000):
            lines = mark_lines(total - sent, sent)
            sock.sendall(b"".join(lines))
            got = 0
            while got < len(lines):
                got += sock.recv(1 << 20).count(b"\n")
            sent = total
            time.sleep(0.3)  # the last frames go out
            print(f"  {total:>10,d} {proc.rss_mb():7.1f}   (tab read {tab.bytes / 1e6:.1f} MB)")
    finally:
        sock.close()
        tab.close()
        proc.stop()


def send_cost() -> None:
    print("viewer, in this process (ViserScene on motoman_sia20d):")
    robot = Robot.from_urdf(ROOT / "robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
    loop = asyncio.new_event_loop()
    world = World(robot)
    scene = ViserScene(Services(world), "127.0.0.1", 0, 100.0)
    world.add_observers([scene])
    scene.start(loop)
    scene.scheduler.stop()  # sends are timed by hand below
    try:
        markers = [
            Marker((i * 1e-3, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0), "sphere")
            for i in range(5000)
        ]
        turn = [0]

        def one_marker() -> None:
            scene.markers.add("motoman_sia20d", markers[turn[0] % 5000])
            turn[0] += 1

        cost = min(timeit.repeat(one_marker, number=10_000, repeat=5)) / 10_000
        print(f"  a marker on the command path (on_marker)   {cost * 1e6:8.2f} us")
        rng = np.random.default_rng(0)
        poses = [robot.random(rng) for _ in range(64)]

        def pose_send() -> None:
            world.robots["motoman_sia20d"].q = poses[turn[0] % 64]
            turn[0] += 1
            scene._dirty.add("motoman_sia20d")
            scene._send()

        cost = min(timeit.repeat(pose_send, number=200, repeat=5)) / 200
        print(f"  a send after a pose change                 {cost * 1e3:8.3f} ms")

        def marker_send() -> None:
            for _ in range(1000):
                one_marker()
            scene._send()

        cost = min(timeit.repeat(marker_send, number=20, repeat=5)) / 20
        print(f"  a send after 1000 new markers (incl. adds)  {cost * 1e3:8.3f} ms")
        print(f"  viser's buffer after it all: {adapter.buffered_messages(scene.server)} messages")
        server = scene.server

        def node_marker() -> None:
            turn[0] += 1
            handle = server.scene.add_icosphere(f"/old/m{turn[0]}", radius=0.015)
            handle.remove()

        cost = min(timeit.repeat(node_marker, number=500, repeat=3)) / 500
        print(f"  before batching: a viser node per marker    {cost * 1e3:8.3f} ms")
    finally:
        scene.stop()
        loop.close()


def main(argv: Sequence[str] | None = None) -> int:
    del argv
    print(f"viser {viser.__version__}, python {sys.version.split()[0]}")
    bystander(viewer=True)
    bystander(viewer=False)
    memory()
    send_cost()
    return 0


if __name__ == "__main__":
    sys.exit(main())
