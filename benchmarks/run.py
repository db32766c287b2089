"""Benchmark c2rviz against the raw-socket ceiling, in one run; print one table.

Usage: ``python benchmarks/run.py [--quick] [--reps N] [--no-viewer]``.

Each repetition launches, as separate processes, the real program
(``python -m c2rviz --port 0 --viser-port P``) and the ceiling
(``benchmarks/ceiling.py``: the leanest asyncio line server; with
``--viser-port`` also the floor for the viewer rows), drives each with the same
clients from this process, and stops them. The table gives the median over the
repetitions, the spread (min..max) and ours/ceiling. Figures only: nothing here
passes or fails on time; the "met" column just reads the targets.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import platform
import re
import signal
import socket
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import clients

ROOT = Path(__file__).resolve().parent.parent
HOST = "127.0.0.1"
N_JOINTS = 7  # the default robot, motoman_sia20d


@dataclass(frozen=True)
class Plan:
    """How much of everything one repetition does."""

    reps: int
    pipelined: int = 100_000
    round_trips: int = 10_000
    clients: int = 50
    per_client: int = 1_000
    frame_samples: int = 200
    flood_s: float = 3.0


FULL = Plan(reps=5)
QUICK = Plan(
    reps=1,
    pipelined=10_000,
    round_trips=500,
    per_client=20,
    frame_samples=15,
    flood_s=0.5,
)


# Processes under test.


@dataclass
class Launched:
    """A server process, its addresses and when they came up."""

    popen: subprocess.Popen[str]
    launched_at: float
    port: int | None = None
    url: str | None = None
    port_open_s: float | None = None
    viewer_s: float | None = None
    output: list[str] = field(default_factory=list)
    _ready: threading.Event = field(default_factory=threading.Event)

    @property
    def address(self) -> tuple[str, int]:
        assert self.port is not None
        return HOST, self.port

    def cpu_s(self) -> float:
        """CPU time [s] used so far by every thread of the process (schedstat, ns)."""
        total = 0
        for task in Path(f"/proc/{self.popen.pid}/task").iterdir():
            with contextlib.suppress(FileNotFoundError, ProcessLookupError):  # a thread ended
                total += int((task / "schedstat").read_text().split()[0])
        return total / 1e9

    def rss_mb(self) -> float:
        """Resident memory [MB] (VmRSS)."""
        status = Path(f"/proc/{self.popen.pid}/status").read_text()
        kib = int(re.search(r"VmRSS:\s+(\d+)", status).group(1))  # type: ignore[union-attr]
        return kib / 1024

    def stop(self) -> None:
        if self.popen.poll() is None:
            self.popen.send_signal(signal.SIGTERM)
            try:
                self.popen.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait(timeout=10)


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind((HOST, 0))
        return sock.getsockname()[1]


# CPUs for the servers and for the clients (this process); None: wherever the OS likes.
SERVER_CPUS: set[int] | None = None
CLIENT_CPUS: set[int] | None = None


def pin_cpus(enabled: bool) -> str:
    """Give the servers one CPU and the clients another, if there are two and we may.

    Unpinned, a request/reply round trip takes ~25 us when the scheduler happens to put
    client and server on one CPU and ~90 us when it wakes the other: medians jump between
    the two. Pinned, every run is the (realistic) two-CPU case.
    """
    global SERVER_CPUS, CLIENT_CPUS
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if not enabled or len(cpus) < 2:
        return "not pinned"
    SERVER_CPUS, CLIENT_CPUS = {cpus[-1]}, set(cpus[:-1])
    os.sched_setaffinity(0, CLIENT_CPUS)
    return f"servers on CPU {cpus[-1]}, clients on CPU {','.join(map(str, cpus[:-1]))}"


def launch(argv: list[str], viewer: bool, timeout_s: float = 60.0) -> Launched:
    """Start ``argv``; return once it prints its command port (and viewer URL)."""
    started = time.perf_counter()
    popen = subprocess.Popen(
        argv,
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    if SERVER_CPUS is not None:  # before it starts any thread: they inherit it
        with contextlib.suppress(ProcessLookupError):
            os.sched_setaffinity(popen.pid, SERVER_CPUS)
    proc = Launched(popen, started)

    def read() -> None:
        assert popen.stdout is not None
        for line in popen.stdout:
            now = time.perf_counter()
            proc.output.append(line)
            if (m := re.search(r"commands on [\d.]+:(\d+)", line)) and proc.port is None:
                proc.port = int(m.group(1))
                proc.port_open_s = now - started
            if (m := re.search(r"viewer at (\S+)", line)) and proc.url is None:
                proc.url = m.group(1)
                proc.viewer_s = now - started
            if proc.port is not None and (proc.url is not None or not viewer):
                proc._ready.set()
        proc._ready.set()  # the process ended

    threading.Thread(target=read, daemon=True).start()
    if not proc._ready.wait(timeout_s) or proc.port is None:
        proc.stop()
        raise RuntimeError(f"{argv} did not start:\n{''.join(proc.output)}")
    return proc


def launch_ours(viewer: bool) -> Launched:
    argv = [sys.executable, "-m", "c2rviz", "--port", "0"]
    argv += ["--viser-port", str(free_port())] if viewer else ["--no-viewer"]
    return launch(argv, viewer)


def launch_ceiling(viewer: bool) -> Launched:
    argv = [sys.executable, str(ROOT / "benchmarks" / "ceiling.py"), "--port", "0"]
    argv += ["--viser-port", str(free_port())] if viewer else []
    return launch(argv, viewer)


# Measurements.


def percentile(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


def ws_url(http_url: str) -> str:
    return re.sub(r"^http", "ws", http_url.rstrip("/"))


def _has_mesh(frame: clients.Frame) -> bool:
    return any("Mesh" in kind or "Glb" in kind or "Box" in kind for kind in frame.types)


async def _scene_ready(proc: Launched) -> float:
    """Seconds from launch until a websocket client has the whole scene, meshes included.

    That is the later of viser's end-of-replay marker and the first frame with a mesh (or
    box): a page that connects then draws the robot.
    """
    assert proc.url is not None
    viewer = clients.ViewerClient(ws_url(proc.url))
    got_mesh = asyncio.Event()
    viewer.on_frame = lambda frame: got_mesh.set() if _has_mesh(frame) else None
    task = asyncio.create_task(viewer.run())
    try:
        await asyncio.wait_for(viewer.replay_done.wait(), 30)
        await asyncio.wait_for(got_mesh.wait(), 30)
    finally:
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
    replay = next(f.at for f in viewer.frames if "ReplayDoneMessage" in f.types)
    mesh = next(f.at for f in viewer.frames if _has_mesh(f))
    return max(replay, mesh) - proc.launched_at


async def _frame_latency(proc: Launched, samples: int) -> list[float]:
    """Seconds from sending ``move`` to the first websocket frame that moves a node."""
    assert proc.url is not None
    viewer = clients.ViewerClient(ws_url(proc.url))
    waiting: list[asyncio.Future[float]] = []

    def on_frame(frame: clients.Frame) -> None:
        if frame.poses and waiting and not waiting[0].done():
            waiting[0].set_result(frame.at)

    viewer.on_frame = on_frame
    task = asyncio.create_task(viewer.run())
    reader, writer = await asyncio.open_connection(*proc.address)
    sock = writer.get_extra_info("socket")
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    lines = clients.move_lines(samples + 1)
    out: list[float] = []
    try:
        await asyncio.wait_for(viewer.replay_done.wait(), 30)
        await asyncio.sleep(0.3)  # let the first scene go out
        loop = asyncio.get_running_loop()
        for k, line in enumerate(lines):
            await asyncio.sleep(0.03 + 0.011 * (k % 3))  # idle scene; off any 100 Hz beat
            waiting[:] = [loop.create_future()]
            sent = time.perf_counter()
            writer.write(line)
            try:
                arrived = await asyncio.wait_for(waiting[0], 2.0)
            except asyncio.TimeoutError:
                arrived = sent + 2.0  # no frame within 2 s: recorded as 2 s
            if await reader.readline() != b"ok\n":
                raise RuntimeError("move was not accepted")
            if k:  # the first one may pay for lazy set-up
                out.append(arrived - sent)
    finally:
        writer.close()
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
    return out


async def _flood_frames(proc: Launched, seconds: float) -> tuple[float, float]:
    """Frames/s reaching the viewer and commands/s while one client floods ``joints``."""
    assert proc.url is not None
    viewer = clients.ViewerClient(ws_url(proc.url))
    task = asyncio.create_task(viewer.run())
    try:
        await asyncio.wait_for(viewer.replay_done.wait(), 30)
        await asyncio.sleep(0.2)
        lines = clients.joints_lines(N_JOINTS, 1000)
        result = await asyncio.to_thread(clients.flood, proc.address, lines, seconds)
        await asyncio.sleep(0.1)  # frames of the last moments of the window
    finally:
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
    frames = viewer.pose_frames_between(result.start, result.end)
    return frames / (result.end - result.start), result.rate


Figures = dict[str, float]


def measure_tcp(proc: Launched, plan: Plan, figures: Figures) -> None:
    lines = clients.joints_lines(N_JOINTS, 1000)
    figures["rss_start"] = proc.rss_mb()
    cpu = proc.cpu_s()
    figures["pipelined"] = clients.pipelined(proc.address, lines, plan.pipelined // len(lines))
    figures["cpu_per_cmd"] = (proc.cpu_s() - cpu) / plan.pipelined * 1e6
    figures["rss_after"] = proc.rss_mb()
    times = clients.request_reply(proc.address, lines, plan.round_trips)
    figures["rr_p50"] = percentile(times, 50) * 1e6
    figures["rr_p99"] = percentile(times, 99) * 1e6
    rate, times = clients.concurrent(proc.address, lines, plan.clients, plan.per_client)
    figures["many_rate"] = rate
    figures["many_p99"] = percentile(times, 99) * 1e6


def measure_viewer(proc: Launched, plan: Plan, figures: Figures) -> float:
    """Rows 4 and 5; returns the TCP commands/s during the flood."""
    times = asyncio.run(_frame_latency(proc, plan.frame_samples))
    figures["frame_p50"] = percentile(times, 50) * 1e3
    figures["frame_p99"] = percentile(times, 99) * 1e3
    figures["flood_fps"], rate = asyncio.run(_flood_frames(proc, plan.flood_s))
    return rate


def run_ceiling(plan: Plan, viewer: bool) -> Figures:
    """The plain ceiling for the TCP rows, then (with viewer rows) the viser floor."""
    figures: Figures = {}
    proc = launch_ceiling(viewer=False)
    try:
        assert proc.port_open_s is not None
        figures["port_open"] = proc.port_open_s
        measure_tcp(proc, plan, figures)
        lines = clients.joints_lines(N_JOINTS, 1000)
        figures["flood_rate"] = clients.flood(proc.address, lines, plan.flood_s).rate
    finally:
        proc.stop()
    if viewer:
        proc = launch_ceiling(viewer=True)
        try:
            figures["scene_ready"] = asyncio.run(_scene_ready(proc))
            measure_viewer(proc, plan, figures)
        finally:
            proc.stop()
    return figures


def run_ours(plan: Plan, viewer: bool) -> Figures:
    """c2rviz, with its viewer when there is one: every row."""
    figures: Figures = {}
    proc = launch_ours(viewer)
    try:
        assert proc.port_open_s is not None
        figures["port_open"] = proc.port_open_s
        if viewer:
            figures["scene_ready"] = asyncio.run(_scene_ready(proc))
        measure_tcp(proc, plan, figures)
        if viewer:
            figures["flood_rate"] = measure_viewer(proc, plan, figures)
        else:
            lines = clients.joints_lines(N_JOINTS, 1000)
            figures["flood_rate"] = clients.flood(proc.address, lines, plan.flood_s).rate
    finally:
        proc.stop()
    return figures


# The table.


@dataclass(frozen=True)
class Row:
    key: str
    label: str
    unit: str
    fmt: str
    target: str
    check: Callable[[float, float | None], bool] | None = None
    """(ours, ratio) -> met."""
    viewer: bool = False


ROWS = [
    Row("pipelined", "1 pipelined, 1 client", "cmd/s", ",.0f", ">= 0.5x", lambda v, r: r >= 0.5),
    Row("cpu_per_cmd", "1 pipelined: server CPU", "us/cmd", ".2f", ""),
    Row("rr_p50", "2 request/reply p50", "us", ".0f", ""),
    Row("rr_p99", "2 request/reply p99", "us", ".0f", "<= 1.5x", lambda v, r: r <= 1.5),
    Row("many_rate", "3 50 clients", "cmd/s", ",.0f", ">= 0.6x", lambda v, r: r >= 0.6),
    Row("many_p99", "3 50 clients p99", "us", ".0f", ""),
    Row("frame_p50", "4 command->frame p50", "ms", ".2f", "<= 5 ms", lambda v, r: v <= 5, True),
    Row("frame_p99", "4 command->frame p99", "ms", ".2f", "<= 20 ms", lambda v, r: v <= 20, True),
    Row("flood_fps", "5 flood: viewer frames", "fps", ".0f", ">= 50", lambda v, r: v >= 50, True),
    Row("flood_rate", "5 flood: TCP meanwhile", "cmd/s", ",.0f", ">= 0.4x", lambda v, r: r >= 0.4),
    Row("port_open", "6 launch->port open", "s", ".3f", "<= 2 s", lambda v, r: v <= 2),
    Row("scene_ready", "6 launch->scene ready", "s", ".3f", "<= 3 s", lambda v, r: v <= 3, True),
    Row("rss_start", "6 RSS after start", "MB", ".0f", "<= 250 MB", lambda v, r: v <= 250),
    Row("rss_after", "6 RSS after 100k cmds", "MB", ".0f", "<= 250 MB", lambda v, r: v <= 250),
]


def summary(values: list[float], fmt: str) -> str:
    if not values:
        return "n/a"
    med = format(statistics.median(values), fmt)
    if len(values) == 1:
        return med
    return f"{med} ({format(min(values), fmt)}..{format(max(values), fmt)})"


def table(ours: list[Figures], ceiling: list[Figures], viewer: bool) -> str:
    header = ("row", "unit", "c2rviz median (min..max)", "ceiling median (min..max)", "ours/ceil",
              "target", "met")  # fmt: skip
    rows = [header]
    for row in ROWS:
        mine = [f[row.key] for f in ours if row.key in f]
        theirs = [f[row.key] for f in ceiling if row.key in f]
        ratio = None
        if mine and theirs and statistics.median(theirs):
            ratio = statistics.median(mine) / statistics.median(theirs)
        met = "-"
        if row.check is not None and mine and (ratio is not None or "x" not in row.target):
            met = "yes" if row.check(statistics.median(mine), ratio) else "NO"
        if row.viewer and not viewer:
            met = "no viewer"
        rows.append((
            row.label,
            row.unit,
            summary(mine, row.fmt),
            summary(theirs, row.fmt),
            f"{ratio:.2f}" if ratio is not None else "n/a",
            row.target,
            met,
        ))  # fmt: skip
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    lines = []
    for k, r in enumerate(rows):
        lines.append("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |")
        if k == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    return "\n".join(lines)


def machine() -> str:
    cpu = "?"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    mem_kib = int(re.search(r"MemTotal:\s+(\d+)", Path("/proc/meminfo").read_text()).group(1))  # type: ignore[union-attr]
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (
        f"machine: {cpu}, {os.cpu_count()} cores, {mem_kib / 2**20:.0f} GiB; "
        f"{platform.system()} {platform.release()}; Python {platform.python_version()}; "
        f"load average {load}"
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one short repetition (for CI)")
    parser.add_argument("--reps", type=int, help="repetitions (default 5; 1 with --quick)")
    parser.add_argument("--no-viewer", action="store_true", help="TCP rows only")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the processes")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else FULL
    if args.reps is not None:
        plan = Plan(**{**plan.__dict__, "reps": max(1, args.reps)})
    viewer = not args.no_viewer and (ROOT / "c2rviz" / "viewer.py").is_file()

    def log(text: str) -> None:
        print(f"  {text}", file=sys.stderr, flush=True)

    pinned = pin_cpus(not args.no_pin)
    print(machine() + f"; {pinned}", flush=True)
    ours: list[Figures] = []
    ceiling: list[Figures] = []
    for rep in range(plan.reps):
        log(f"repetition {rep + 1}/{plan.reps}")
        # Alternate who goes first, so a drift in the machine's load favours neither.
        if rep % 2 == 0:
            ceiling.append(run_ceiling(plan, viewer))
            ours.append(run_ours(plan, viewer))
        else:
            ours.append(run_ours(plan, viewer))
            ceiling.append(run_ceiling(plan, viewer))
        log(
            f"c2rviz {ours[-1]['pipelined']:,.0f} cmd/s pipelined, "
            f"ceiling {ceiling[-1]['pipelined']:,.0f}"
        )
    print(
        f"{plan.reps} repetition(s); pipelined {plan.pipelined:,} joints lines; "
        f"{plan.round_trips:,} round trips; {plan.clients} clients x {plan.per_client:,}; "
        f"{plan.frame_samples} command->frame samples; flood {plan.flood_s:g} s"
        + ("" if viewer else "; viewer rows skipped (no c2rviz/viewer.py or --no-viewer)")
    )
    print(table(ours, ceiling, viewer))
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
