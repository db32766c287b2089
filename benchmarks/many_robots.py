"""Many robots in one cell, all moving, a page open: the server's CPU, the frames each robot
gets on the page, and a bystander's round trips.

Usage: ``python benchmarks/many_robots.py [--robots 64] [--seconds 10] [--quick|--smoke]
[--no-pin] [--page-process [--page-anywhere]]`` (``--quick``: 8 robots for 2 s;
``--smoke``, the test suite's: every row on the least work, 2 robots for half a second
after half a second's warm-up).

A temporary ini holds ``[cell:many]`` with N motoman_sia20d members on a grid, every
port 0 (the program picks free ones). The program runs with its viewer; one websocket
client (``loadgen.ViewerClient``) decodes every frame and counts, per robot, the frames
that move one of its links (a ``SetOrientationMessage`` under ``/robots/<name>/``). One
driver connection keeps every robot moving at speed 100 (``motion follow``, a new far
target for each robot every half second, switching robots with ``robot NAME``); a
bystander process does ``where`` request/reply on the first robot's port meanwhile.

Figures, printed beside their goals (issue 30; with ``--page-process`` issue 40's: the
command process <= 0.5 core, a bystander's p99 <= 2 ms): the server's CPU [share of one
core], frames/s reaching the page per robot (the lowest and the median), the bystander's
p50 and p99 [ms]. The server is pinned to one CPU and the clients to the other, as in
``run.py``. ``--page-process`` runs the program with ``--page-process`` (docs/page.md):
the page process shares the server's CPU (it inherits the pin; ``--page-anywhere`` lets
it run on every CPU, where it competes with the page client's decoding) and its CPU is a
row of its own; "server CPU" is then the command process's alone.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import re
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import loadgen
from line_clients import Bystander, LineClient, percentile
from processes import HOST, Launched, free_port, launch, pin_cpus
from report import machine

GOALS = {"cpu": 1.0, "fps": 30.0, "p99_ms": 5.0}
PAGE_PROCESS_GOALS = {"cpu": 0.5, "fps": 30.0, "p99_ms": 2.0}
"""Issue 40's, with ``--page-process``: the command process's CPU alone, a tighter p99."""
FAR = ("90,45,-30,-30,0,60,0", "-90,-45,30,30,0,-60,0")  # degrees: two far targets


def write_cell(folder: Path, count: int) -> Path:
    """A cell of ``count`` motoman_sia20d on a grid 2 m apart."""
    side = max(1, round(count**0.5))
    names = [f"r{i}" for i in range(count)]
    lines = ["[options]", "host = 127.0.0.1", "", "[cell:many]", f"robots = {' '.join(names)}"]
    for i, name in enumerate(names):
        x, y = 2.0 * (i % side), 2.0 * (i // side)
        lines += [
            "",
            f"[{name}]",
            "robot = motoman_sia20d",
            f"origin = {x},{y},0,0,0,0",
            "port = 0",
        ]
    path = folder / "many.ini"
    path.write_text("\n".join(lines) + "\n")
    return path


def member_ports(proc: Launched, count: int, timeout_s: float = 120.0) -> dict[str, int]:
    """Each member's command port, from the banner."""
    deadline = time.perf_counter() + timeout_s
    while time.perf_counter() < deadline:
        ports = {}
        for line in list(proc.output):
            if m := re.search(r"c2rviz: (r\d+): commands on [\d.]+:(\d+)", line):
                ports[m.group(1)] = int(m.group(2))
        if len(ports) == count and proc.url is not None:
            return ports
        time.sleep(0.05)
    raise RuntimeError("the cell did not come up:\n" + "".join(proc.output))


class PageCounter:
    """A page on its own thread: counts, per robot, the frames that move its links."""

    def __init__(self, url: str) -> None:
        self.url = url
        self.frames: Counter[str] = Counter()
        self.counting = False
        self._ready = threading.Event()
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        if not self._ready.wait(60):
            raise RuntimeError("the page did not connect")

    def _run(self) -> None:
        asyncio.set_event_loop(self._loop)
        self._task = self._loop.create_task(self._view())
        with contextlib.suppress(asyncio.CancelledError):
            self._loop.run_until_complete(self._task)

    async def _view(self) -> None:
        viewer = loadgen.ViewerClient(self.url)
        viewer.on_messages = self._messages
        ready = asyncio.Event()
        waiter = asyncio.ensure_future(viewer.run(ready))
        await ready.wait()
        self._ready.set()
        await waiter

    def _messages(self, at: float, messages: list[dict[str, Any]]) -> None:
        if not self.counting:
            return
        moved = set()
        for m in messages:
            if m.get("type") == "SetOrientationMessage":
                name = m.get("name", "")
                if name.startswith("/robots/"):
                    moved.add(name.split("/")[2])
        self.frames.update(moved)

    def stop(self) -> None:
        self._loop.call_soon_threadsafe(self._task.cancel)
        self._thread.join(timeout=30)


def drive(port: int, names: Sequence[str], until: float) -> int:
    """Keep every robot moving (``motion follow`` at speed 100): a far target each half
    second, alternating. Returns the commands sent."""
    client = LineClient((HOST, port))
    for line in ("degrees", "motion follow", "speed 100"):
        client.ok(line)
    sent, k = 0, 0
    while time.perf_counter() < until:
        batch = []
        for name in names:
            batch += [f"robot {name}", f"joints {FAR[k % 2]}"]
        for line in batch:
            client.ok(line)
        sent += len(batch)
        k += 1
        time.sleep(0.5)
    client.close()
    return sent


def page_process(pid: int) -> int | None:
    """The page process of the program ``pid`` (``--page-process``), if it runs one: its
    one child (forked at start, so its command line is the program's)."""
    for entry in Path("/proc").iterdir():
        with contextlib.suppress(OSError, ValueError, IndexError):
            if (
                entry.name.isdigit()
                and int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1]) == pid
            ):
                return int(entry.name)
    return None


def tasks_cpu_s(pid: int | None) -> float:
    """CPU time [s] of every thread of ``pid`` (0 for None)."""
    if pid is None:
        return 0.0
    total = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(OSError):
            total += int((task / "schedstat").read_text().split()[0])
    return total / 1e9


def let_loose(pid: int) -> None:
    """Every thread of ``pid`` may run on every CPU (it inherited the server's pin)."""
    every = set(range(os.cpu_count() or 1))
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(OSError):
            os.sched_setaffinity(int(task.name), every)


def measure(
    count: int, seconds: float, page: bool = False, loose: bool = False, warm_s: float = 3.0
) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as folder:
        ini = write_cell(Path(folder), count)
        argv = [sys.executable, "-m", "c2rviz", "--cell", str(ini), "--port", "0"]
        argv += ["--page-process"] if page else []
        proc = launch([*argv, "--viser-port", str(free_port())], viewer=True, timeout_s=180)
        try:
            ports = member_ports(proc, count)
            drawer = page_process(proc.popen.pid) if page else None
            if drawer is not None and loose:
                let_loose(drawer)
            counter = PageCounter(loadgen.ws_url(proc.url))  # type: ignore[arg-type]
            names = sorted(ports, key=lambda n: int(n[1:]))
            warm = time.perf_counter() + warm_s
            driver = threading.Thread(
                target=drive, args=(ports[names[0]], names, warm + seconds + 1.0), daemon=True
            )
            driver.start()
            while time.perf_counter() < warm:
                time.sleep(0.05)
            bystander = Bystander((HOST, ports[names[0]]), seconds, "where")
            cpu0, t0 = proc.cpu_s(), time.perf_counter()
            drew0 = tasks_cpu_s(drawer)
            counter.counting = True
            while bystander.running():
                time.sleep(0.05)
            counter.counting = False
            cpu1, t1 = proc.cpu_s(), time.perf_counter()
            drew1 = tasks_cpu_s(drawer)
            times, _ = bystander.result()
            driver.join(timeout=60)
            counter.stop()
            rates = sorted(counter.frames.get(n.lower(), 0) / (t1 - t0) for n in names)
            return {
                "cpu": (cpu1 - cpu0) / (t1 - t0),
                "page_cpu": (drew1 - drew0) / (t1 - t0),
                "fps_min": rates[0],
                "fps_median": rates[len(rates) // 2],
                "p50_ms": percentile(times, 50) * 1e3,
                "p99_ms": percentile(times, 99) * 1e3,
            }
        finally:
            proc.stop()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=64, help="robots in the cell (64)")
    parser.add_argument("--seconds", type=float, default=10.0, help="measured time (10)")
    parser.add_argument("--quick", action="store_true", help="8 robots for 2 s")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the processes")
    parser.add_argument(
        "--page-process", action="store_true", help="the page in a process of its own"
    )
    parser.add_argument(
        "--page-anywhere",
        action="store_true",
        help="with --page-process: let the page process run on every CPU (default: the "
        "server's, as it inherits)",
    )
    args = parser.parse_args(argv)
    count, seconds, warm_s = (
        (2, 0.5, 0.5)
        if args.smoke
        else (8, 2.0, 3.0)
        if args.quick
        else (args.robots, args.seconds, 3.0)
    )
    print(machine())
    where = "any CPU" if args.page_anywhere else "the server's CPU"
    how = f"; the page in its own process (on {where})" if args.page_process else ""
    print(f"{count} motoman_sia20d moving, a page open; {pin_cpus(not args.no_pin)}{how}")
    got = measure(count, seconds, args.page_process, args.page_anywhere, warm_s)
    goals = PAGE_PROCESS_GOALS if args.page_process else GOALS
    rows = [
        ("server CPU [cores]", got["cpu"], "<=", goals["cpu"]),
        *([("page process CPU [cores]", got["page_cpu"], "", None)] if args.page_process else []),
        ("page frames/s, lowest robot", got["fps_min"], ">=", goals["fps"]),
        ("page frames/s, median robot", got["fps_median"], ">=", goals["fps"]),
        ("bystander where p50 [ms]", got["p50_ms"], "", None),
        ("bystander where p99 [ms]", got["p99_ms"], "<=", goals["p99_ms"]),
    ]
    print("| figure | value | goal | met |")
    print("|---|---|---|---|")
    for name, value, how, goal in rows:
        if goal is None:
            print(f"| {name} | {value:.2f} | | |")
            continue
        met = value <= goal if how == "<=" else value >= goal
        print(f"| {name} | {value:.2f} | {how} {goal:g} | {'yes' if met else 'no'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
