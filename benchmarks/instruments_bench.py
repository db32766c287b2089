"""The page as an instrument: what its plots cost, and what a recorded page costs.

Usage: ``python benchmarks/instruments_bench.py [--quick] [--no-browser]``.

Prints one table (``machine: ...`` first), each row with its goal:

* live page, 1 and 8 robots (a cell of motoman_sia20d), every robot in a long motion
  (``motion follow`` between two far targets, the next one sent on arrival), one
  viewer tab reading everything: the frames a second that reach the tab with a new
  arm pose, and the server's CPU [% of one core], with the plots on, then off (the
  tab clears each robot's ``Plots`` checkbox, as a page does); the difference is
  what the plots cost.
* the recorded page of a 10-minute 100 Hz recording (written by the real recorder
  on a stepped clock): its size per minute, and in headless Chromium the time from
  opening the file to the first frame posed.
* ``record stop`` of a 1-hour 100 Hz recording (the same way): its time (NAME.txt
  put together and NAME.html written, viser already loaded) and the peak memory it
  adds (the process's peak RSS, reset just before).

``--quick`` measures 2 s windows and a 1-minute "hour" (the rows say so); ``--smoke``
(the test suite's: every row, the least work) half-second windows and a 10-second "hour"
and "10 minutes" (one recording). Figures
only: nothing here passes or fails; the "met" column reads the goals.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import msgspec
import viser
import zstandard
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

sys.path.insert(0, str(Path(__file__).resolve().parent))
from processes import ROOT, Launched, launch  # noqa: E402
from report import machine  # noqa: E402

CAMERA = {
    "type": "ViewerCameraMessage",
    **{"wxyz": [1.0, 0.0, 0.0, 0.0], "position": [3.0, 0.0, 1.0], "fov": 1.0},
    **{"near": 0.01, "far": 100.0, "image_height": 700, "image_width": 1000},
    **{"look_at": [0.0, 0.0, 0.5], "up_direction": [0.0, 0.0, 1.0]},
}
URDF = ROOT / "robots" / "motoman_sia20d" / "robot.urdf"
TARGETS = ("150,60,-90,60,90,60,90", "-150,-60,90,-60,-90,-60,-90")  # degrees, far apart


class Tab:
    """A viewer tab reading every frame on a thread: counts the frames carrying a new pose
    of the watched link, and keeps the uuids of the ``Plots`` checkboxes."""

    def __init__(self, url: str, link: str) -> None:
        self.ws = connect(
            url.replace("http://", "ws://"),
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            max_size=None,
        )
        self.ws.send(msgspec.msgpack.encode(CAMERA))
        self.link = link
        self.pose_frames: list[float] = []  # arrival times of frames with a new pose
        self.plots: list[str] = []
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        inflate = zstandard.ZstdDecompressor()
        try:
            while True:
                frame = self.ws.recv()
                assert isinstance(frame, bytes)
                size = int.from_bytes(frame[:8], "little")
                packed = int.from_bytes(frame[8:16], "little")
                body = inflate.decompress(frame[16 : 16 + packed], size)
                messages = msgspec.msgpack.decode(body)["messages"]
                posed = False
                for message in messages:
                    kind = message.get("type", "")
                    if kind == "SetOrientationMessage" and message.get("name") == self.link:
                        posed = True
                    elif kind == "GuiCheckboxMessage" and message["props"]["label"] == "Plots":
                        with self.lock:
                            self.plots.append(message["uuid"])
                if posed:
                    with self.lock:
                        self.pose_frames.append(time.perf_counter())
        except (ConnectionClosed, OSError):
            pass

    def frames_between(self, start: float, end: float) -> int:
        with self.lock:
            return sum(start <= t < end for t in self.pose_frames)

    def set_plots(self, on: bool) -> None:
        with self.lock:
            uuids = list(self.plots)
        for uuid in uuids:
            update = {"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": on}}
            self.ws.send(msgspec.msgpack.encode(update))

    def close(self) -> None:
        self.ws.close()
        self.thread.join(timeout=10)


class Mover:
    """Keeps every robot of a program moving: one client per robot, ``motion on``, the
    other far target sent at each arrival."""

    def __init__(self, address: tuple[str, int], robots: Sequence[str]) -> None:
        self.stopped = threading.Event()
        self.threads = [
            threading.Thread(target=self._move, args=(address, robot), daemon=True)
            for robot in robots
        ]
        for thread in self.threads:
            thread.start()

    def _move(self, address: tuple[str, int], robot: str) -> None:
        with socket.create_connection(address) as sock, sock.makefile("rb") as replies:

            def ask(line: str) -> str:
                sock.sendall(line.encode() + b"\n")
                return replies.readline().decode().strip()

            for line in (f"robot {robot}", "degrees", "motion on", "speed 8"):
                ask(line)
            k = 0
            while not self.stopped.is_set():
                ask(f"j {TARGETS[k % 2]}")  # the reply comes on arrival
                k += 1

    def stop(self) -> None:
        self.stopped.set()


def live(robots: int, window_s: float, settle_s: float = 1.0) -> dict[str, tuple[float, float]]:
    """(frames a second to the tab, server CPU %) with the plots on, then off; each
    measured ``window_s`` after ``settle_s`` (twice that at first: charts drawn once)."""
    with tempfile.TemporaryDirectory() as folder:
        names = [f"arm{k}" for k in range(robots)]
        ini = Path(folder) / "cell.ini"
        ini.write_text(
            "[cell:bench]\nrobots = "
            + " ".join(names)
            + "\n"
            + "".join(
                f"[{name}]\nurdf = {URDF}\nbase = base_link\neelink = link_t\n"
                f"origin = {1.5 * (k % 4)},{1.5 * (k // 4)},0,0,0,0\nport = 0\n"
                for k, name in enumerate(names)
            )
        )
        argv = [sys.executable, "-m", "c2rviz", "--cell", str(ini), "--viser-port", "0"]
        proc = launch(argv, viewer=True, timeout_s=120)
        tab = Tab(proc.url or "", f"/robots/{names[0]}/links/base_link/link_s")
        mover = Mover(proc.address, names)
        try:
            time.sleep(2 * settle_s)  # every robot under way, every chart drawn once
            out = {}
            for mode in ("on", "off"):
                tab.set_plots(mode == "on")
                time.sleep(settle_s)
                out[mode] = measure(proc, tab, window_s)
            return out
        finally:
            mover.stop()
            tab.close()
            proc.stop()


def measure(proc: Launched, tab: Tab, window_s: float) -> tuple[float, float]:
    cpu, start = proc.cpu_s(), time.perf_counter()
    time.sleep(window_s)
    end = time.perf_counter()
    used = proc.cpu_s() - cpu
    return tab.frames_between(start, end) / (end - start), 100.0 * used / (end - start)


# Recordings: made by the real recorder on a stepped clock, in a child process.

RECORD = r"""
import json, math, os, resource, sys, time
from pathlib import Path
import numpy as np
from c2rviz.app.program import write_page
from c2rviz.observers.recordings import finish
from c2rviz.view import record_page  # viser loaded, as in a program with its page open
from c2rviz.world.clock import Clock
from c2rviz.world.world import World

class Stepped(Clock):
    t = 1000.0
    def now(self):
        return self.t

seconds, folder, name = float(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
from c2rviz.robot.model import Robot
robot = Robot.from_urdf("robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
clock = Stepped()
world = World(robot, clock=clock)
from c2rviz.session import Services
services = Services(world, record_dir=folder)
recording = services.recordings.start(name, world.default)
state = world.state()
frames = int(seconds * 100)
for k in range(1, frames + 1):
    clock.t += 0.01
    world.set_q([0.8 * math.sin(0.3 * k / 100 + j) for j in range(robot.n)])
    if k % 6000 == 0:
        world.add_marker(None, (1.0, 0.0, 0.0), "sphere")
for part in recording.recorders.values():
    world.remove_observer(part)
    part.stop()
def rss_kib(key):
    text = Path("/proc/self/status").read_text()
    return int(text.split(key + ":")[1].split()[0])
try:
    Path("/proc/self/clear_refs").write_text("5")  # the peak RSS starts again from now
    reset = True
except OSError:
    reset = False
before = rss_kib("VmRSS")
start = time.perf_counter()
(done,) = finish(recording, {world.default: state}, [write_page])
took = time.perf_counter() - start
peak = rss_kib("VmHWM")
print(json.dumps({
    "seconds": took, "extra_mb": (peak - before) / 1024, "reset": reset,
    "html": str(done.html), "html_bytes": done.html.stat().st_size,
    "csv_mb": done.csv.stat().st_size / 1e6, "frames": done.frames,
}))
"""


def recording(seconds: float, folder: Path, name: str) -> dict[str, object]:
    done = subprocess.run(
        [sys.executable, "-c", RECORD, str(seconds), str(folder), name],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=3600,
    )
    if done.returncode:
        raise RuntimeError(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


FIRST_FRAME = "() => window.__c2rvizPlayer && window.__c2rvizPlayer.state().frame >= 0"
SCENE_SHOWN = """() => {
  const tree = window.__viserSceneTree, m = window.__viserMutable;
  return !!(tree && m && Object.keys(tree.getState()).some((n) => n.endsWith("/link_t")));
}"""


def open_s(html: Path, until: str, reps: int) -> float:
    """Opening ``html`` in headless Chromium until ``until`` holds [s], best of ``reps``."""
    from playwright.sync_api import sync_playwright

    args = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking"]
    best = math.inf
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=args)
        try:
            for _ in range(reps):
                page = browser.new_page(viewport={"width": 1100, "height": 760})
                start = time.perf_counter()
                page.goto(html.as_uri())
                page.wait_for_function(until, timeout=120_000, polling=10)
                best = min(best, time.perf_counter() - start)
                page.close()
        finally:
            browser.close()
    return best


def viser_page(folder: Path) -> Path:
    """viser's own static page of the same scene (no recording, no player): the floor."""
    import pinocchio as pin

    sys.path.insert(0, str(ROOT))
    from c2rviz.robot.model import Robot
    from c2rviz.robot.visuals import load_link_geometry
    from c2rviz.view import adapter
    from c2rviz.view.robot_view import RobotView

    robot = Robot.from_urdf(URDF, "base_link", "link_t")
    server = adapter.start("127.0.0.1", 0)
    try:
        server.scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        RobotView(server, "arm", robot, pin.SE3.Identity(), load_link_geometry(robot.source), "r")
        path = folder / "viser.html"
        path.write_text(server.get_scene_serializer().as_html(), encoding="utf-8")
    finally:
        adapter.stop(server)
    return path


def row(label: str, unit: str, value: float, goal: str = "", met: bool | None = None) -> str:
    shown = f"{value:,.1f}" if math.isfinite(value) else "n/a"
    verdict = "" if met is None else "yes" if met else "NO"
    return f"| {label} | {unit} | {shown} | {goal} | {verdict} |"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="short windows, a 1-minute hour")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    parser.add_argument("--no-browser", action="store_true", help="skip the load-time rows")
    args = parser.parse_args(argv)
    args.quick = args.quick or args.smoke
    window = 0.5 if args.smoke else 2.0 if args.quick else 10.0
    settle = 0.3 if args.smoke else 1.0
    hour = 10.0 if args.smoke else 60.0 if args.quick else 3600.0
    ten = 10.0 if args.smoke else 60.0 if args.quick else 600.0
    print(f"{machine()}; viser {viser.__version__}")
    rows = ["| row | unit | figure | goal | met |", "|---|---|---|---|---|"]
    add = rows.append
    for robots in (1, 8):
        figures = live(robots, window, settle)
        (fps_on, cpu_on), (fps_off, cpu_off) = figures["on"], figures["off"]
        name = f"{robots} robot{'s' if robots > 1 else ''}"
        add(row(f"{name}: frames/s to a tab, plots on", "1/s", fps_on, ">= 50", fps_on >= 50))
        add(row(f"{name}: frames/s to a tab, plots off", "1/s", fps_off))
        add(row(f"{name}: server CPU, plots on", "% core", cpu_on))
        add(row(f"{name}: server CPU, plots off", "% core", cpu_off))
        extra = cpu_on - cpu_off
        add(row(f"{name}: CPU the plots add", "% core", extra, "<= 20", extra <= 20))
    with tempfile.TemporaryDirectory() as folder:
        tag = "10 s (smoke)" if args.smoke else "1 min (quick)" if args.quick else "10 min"
        made = recording(ten, Path(folder), "ten")
        floor = viser_page(Path(folder))
        size = float(made["html_bytes"])  # type: ignore[arg-type]
        per_minute = (size - floor.stat().st_size) / 1e3 / (ten / 60.0)
        add(row(f"recorded page, {tag}: size", "MB", size / 1e6))
        add(row("recorded page: size per minute past viser's page", "kB/min", per_minute))
        if not args.no_browser:
            reps = 1 if args.quick else 3
            load = open_s(Path(str(made["html"])), FIRST_FRAME, reps)
            add(row(f"recorded page, {tag}: open to first frame", "s", load, "<= 2", load <= 2))
            load = open_s(floor, SCENE_SHOWN, reps)
            add(row("viser's own page of the robot: open to scene", "s", load))
        tag = "10 s (smoke)" if args.smoke else "1 min (quick)" if args.quick else "1 h"
        if hour != ten:  # (the smoke's "hour" is its ten minutes: one recording serves both)
            made = recording(hour, Path(folder), "hour")
        took, extra = float(made["seconds"]), float(made["extra_mb"])  # type: ignore[arg-type]
        note = "" if made["reset"] else " (peak not reset)"
        add(row(f"record stop, {tag} at 100 Hz: time", "s", took, "<= 2", took <= 2.0))
        add(row(f"record stop, {tag}: extra memory{note}", "MB", extra, "<= 100", extra <= 100))
        add(row(f"record stop, {tag}: NAME.csv", "MB", float(made["csv_mb"])))  # type: ignore[arg-type]
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    with contextlib.suppress(KeyboardInterrupt):
        sys.exit(main())
    sys.exit(130)
