"""Benchmark c2rviz against the raw-socket ceiling, in one run; print one table.

Usage: ``python benchmarks/run.py [--quick] [--reps N] [--no-viewer] [--no-pin] [--tab]
[--page-process]``.

Each repetition launches, as separate processes, the real program
(``python -m c2rviz --port 0 --viser-port P``) and the ceiling
(``benchmarks/ceiling.py``: the leanest asyncio line server; with
``--viser-port`` also the floor for the viewer rows), drives each with the same
clients from this process, and stops them. The table gives the median over the
repetitions, the spread (min..max) and ours/ceiling. Figures only: nothing here
passes or fails on time; the "met" column just reads the targets.

``--tab`` measures the TCP rows of c2rviz with a tab open and its arm moving (a
``ViewerClient`` decoding every frame, and a second client keeping joint 0 moving
with ``move``), as issue 40 asks; the ceiling is measured as always.
``--page-process`` runs c2rviz with ``--page-process`` (the page in a process of its
own, docs/page.md).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import socket
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import loadgen
from processes import ROOT, Launched, free_port, launch, launch_ceiling, pin_cpus
from report import Figures, machine, table

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
SMOKE = Plan(  # the test suite's run: every row, the least work
    reps=1,
    pipelined=2_000,
    round_trips=200,
    per_client=10,
    frame_samples=10,
    flood_s=1.0,  # 0.3 s once showed the ceiling's viewer no frame at a load of 7 (ratio n/a)
)


# Measurements.


def percentile(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


def _has_mesh(frame: loadgen.Frame) -> bool:
    return any("Mesh" in kind or "Glb" in kind or "Box" in kind for kind in frame.types)


async def _scene_ready(proc: Launched) -> float:
    """Seconds from launch until a websocket client has the whole scene, meshes included.

    That is the later of viser's end-of-replay marker and the first frame with a mesh (or
    box): a page that connects then draws the robot.
    """
    assert proc.url is not None
    viewer = loadgen.ViewerClient(loadgen.ws_url(proc.url))
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
    viewer = loadgen.ViewerClient(loadgen.ws_url(proc.url))
    waiting: list[asyncio.Future[float]] = []

    def on_frame(frame: loadgen.Frame) -> None:
        if frame.poses and waiting and not waiting[0].done():
            waiting[0].set_result(frame.at)

    viewer.on_frame = on_frame
    task = asyncio.create_task(viewer.run())
    reader, writer = await asyncio.open_connection(*proc.address)
    sock = writer.get_extra_info("socket")
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    lines = loadgen.move_lines(samples + 1)
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
    viewer = loadgen.ViewerClient(loadgen.ws_url(proc.url))
    task = asyncio.create_task(viewer.run())
    try:
        await asyncio.wait_for(viewer.replay_done.wait(), 30)
        await asyncio.sleep(0.2)
        lines = loadgen.joints_lines(N_JOINTS, 1000)
        result = await asyncio.to_thread(loadgen.flood, proc.address, lines, seconds)
        await asyncio.sleep(0.1)  # frames of the last moments of the window
    finally:
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
    frames = viewer.pose_frames_between(result.start, result.end)
    return frames / (result.end - result.start), result.rate


def measure_tcp(proc: Launched, plan: Plan, figures: Figures) -> None:
    lines = loadgen.joints_lines(N_JOINTS, 1000)
    figures["rss_start"] = proc.rss_mb()
    cpu = proc.cpu_s()
    figures["pipelined"] = loadgen.pipelined(proc.address, lines, plan.pipelined // len(lines))
    figures["cpu_per_cmd"] = (proc.cpu_s() - cpu) / plan.pipelined * 1e6
    figures["rss_after"] = proc.rss_mb()
    times = loadgen.request_reply(proc.address, lines, plan.round_trips)
    figures["rr_p50"] = percentile(times, 50) * 1e6
    figures["rr_p99"] = percentile(times, 99) * 1e6
    rate, times = loadgen.concurrent(proc.address, lines, plan.clients, plan.per_client)
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
        lines = loadgen.joints_lines(N_JOINTS, 1000)
        figures["flood_rate"] = loadgen.flood(proc.address, lines, plan.flood_s).rate
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


@contextlib.contextmanager
def tab_and_motion(proc: Launched) -> Iterator[None]:
    """A tab open (a ``ViewerClient`` decoding every frame) and joint 0 kept moving by a
    client of its own, on a thread, for the time of the block."""
    assert proc.url is not None
    done = threading.Event()
    ready = threading.Event()

    async def keep_moving() -> None:
        viewer = loadgen.ViewerClient(loadgen.ws_url(proc.url or ""))
        shown = asyncio.Event()
        task = asyncio.create_task(viewer.run(shown))
        reader, writer = await asyncio.open_connection(*proc.address)
        try:
            await asyncio.wait_for(shown.wait(), 30)
            for line in (b"degrees\n", b"motion on\n", b"speed 100\n"):
                writer.write(line)
                await reader.readline()
            ready.set()
            k = 0
            while not done.is_set():
                writer.write(f"move 0 {(-1) ** k * 90}\n".encode())  # ok at arrival
                await reader.readline()
                k += 1
        finally:
            ready.set()
            writer.close()
            task.cancel()
            await asyncio.gather(task, return_exceptions=True)

    thread = threading.Thread(target=lambda: asyncio.run(keep_moving()), daemon=True)
    thread.start()
    ready.wait(60)
    try:
        yield
    finally:
        done.set()
        thread.join(timeout=30)


def launch_ours(viewer: bool, page_process: bool = False) -> Launched:
    argv = [sys.executable, "-m", "c2rviz", "--port", "0"]
    argv += ["--viser-port", str(free_port())] if viewer else ["--no-viewer"]
    argv += ["--page-process"] if page_process and viewer else []
    return launch(argv, viewer)


def run_ours(plan: Plan, viewer: bool, tab: bool = False, page_process: bool = False) -> Figures:
    """c2rviz, with its viewer when there is one: every row (``tab``: the TCP rows with a
    tab open and the arm moving)."""
    figures: Figures = {}
    proc = launch_ours(viewer, page_process)
    try:
        assert proc.port_open_s is not None
        figures["port_open"] = proc.port_open_s
        if viewer:
            figures["scene_ready"] = asyncio.run(_scene_ready(proc))
        with tab_and_motion(proc) if tab and viewer else contextlib.nullcontext():
            measure_tcp(proc, plan, figures)
        if viewer:
            figures["flood_rate"] = measure_viewer(proc, plan, figures)
        else:
            lines = loadgen.joints_lines(N_JOINTS, 1000)
            figures["flood_rate"] = loadgen.flood(proc.address, lines, plan.flood_s).rate
    finally:
        proc.stop()
    return figures


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one short repetition (for CI)")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    parser.add_argument("--reps", type=int, help="repetitions (default 5; 1 with --quick)")
    parser.add_argument("--no-viewer", action="store_true", help="TCP rows only")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the processes")
    parser.add_argument(
        "--tab", action="store_true", help="c2rviz's TCP rows with a tab open and the arm moving"
    )
    parser.add_argument(
        "--page-process", action="store_true", help="c2rviz with the page in its own process"
    )
    args = parser.parse_args(argv)
    plan = SMOKE if args.smoke else QUICK if args.quick else FULL
    if args.reps is not None:
        plan = Plan(**{**plan.__dict__, "reps": max(1, args.reps)})
    viewer = not args.no_viewer and (ROOT / "c2rviz" / "view" / "viser_scene.py").is_file()

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
            ours.append(run_ours(plan, viewer, args.tab, args.page_process))
        else:
            ours.append(run_ours(plan, viewer, args.tab, args.page_process))
            ceiling.append(run_ceiling(plan, viewer))
        log(
            f"c2rviz {ours[-1]['pipelined']:,.0f} cmd/s pipelined, "
            f"ceiling {ceiling[-1]['pipelined']:,.0f}"
        )
    print(
        f"{plan.reps} repetition(s); pipelined {plan.pipelined:,} joints lines; "
        f"{plan.round_trips:,} round trips; {plan.clients} clients x {plan.per_client:,}; "
        f"{plan.frame_samples} command->frame samples; flood {plan.flood_s:g} s"
        + ("" if viewer else "; viewer rows skipped (no c2rviz/view/viser_scene.py or --no-viewer)")
        + ("; c2rviz's TCP rows with a tab open and the arm moving" if args.tab else "")
        + ("; c2rviz with --page-process" if args.page_process else "")
    )
    print(
        "ours/ceil is the ratio of the medians: higher is better for rates, lower for times "
        "and memory; rows 4, 5 (frames) and scene ready compare with the viser floor"
    )
    print(table(ours, ceiling, viewer))
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
