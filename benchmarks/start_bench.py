"""How long the program takes to start: launch until its banner (every door open, the page
served), and the CPU it spent to get there.

Usage: ``python benchmarks/start_bench.py [--reps 10] [--no-pin]``.

Each repetition launches ``python -m c2rviz`` in four ways, in turn: as a user starts it
(the page, CRCL and rosbridge, every port free), the same with ``--page-process`` (the
page in a process of its own, issue 40), ``--no-viewer``, and the command port alone
(``--no-viewer --no-crcl --no-rosbridge``). A launch counts until the line ``commands on
...`` (and the viewer's URL, when there is a viewer): the program prints its banner only
once every door is open. Printed: the median and spread of the wall time, of the CPU time
at that moment (the program's and its page process's) and of the resident memory then
(both processes'), beside the goals (issue 30: start <= 1 s; issue 40: the same with
``--page-process``, and both processes <= 250 MB).
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import sys
from collections.abc import Sequence
from pathlib import Path

from processes import launch, pin_cpus
from report import machine

GOAL_S = 1.0
GOAL_MB = 250.0
GOALS = ("as a user starts it", "--page-process")
"""The ways with a start goal (the others show what the viewer costs)."""
WAYS = {
    "as a user starts it": [],
    "--page-process": ["--page-process"],
    "--no-viewer": ["--no-viewer"],
    "command port alone": ["--no-viewer", "--no-crcl", "--no-rosbridge"],
}


def children(pid: int) -> list[int]:
    """The processes ``pid`` started (its page process), from /proc."""
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(FileNotFoundError, ProcessLookupError):
            found += [int(c) for c in (task / "children").read_text().split()]
    return found


def _cpu_s(pid: int) -> float:
    total = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(FileNotFoundError, ProcessLookupError):
            total += int((task / "schedstat").read_text().split()[0])
    return total / 1e9


def _rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def once(extra: list[str]) -> tuple[float, float, float]:
    """(launch -> banner [s], CPU time of the program and its children by then [s], their
    resident memory then [MB])."""
    argv = [sys.executable, "-m", "c2rviz", "--port", "0", "--crcl-port", "0"]
    argv += ["--rosbridge-port", "0", "--viser-port", "0", *extra]
    proc = launch(argv, viewer="--no-viewer" not in extra)
    try:
        pids = [proc.popen.pid, *children(proc.popen.pid)]
        cpu = sum(_cpu_s(pid) for pid in pids)
        rss = sum(_rss_mb(pid) for pid in pids)
        ready = max(proc.port_open_s or 0.0, proc.viewer_s or 0.0)
        return ready, cpu, rss
    finally:
        proc.stop()


def spread(values: list[float]) -> str:
    return f"{statistics.median(values):.3f} ({min(values):.3f}..{max(values):.3f})"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=10, help="launches of each way")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the process")
    args = parser.parse_args(argv)
    print(machine() + f"; {pin_cpus(not args.no_pin)}", flush=True)
    figures: dict[str, list[tuple[float, float, float]]] = {way: [] for way in WAYS}
    for rep in range(max(1, args.reps)):
        for way, extra in WAYS.items():  # in turn, so a drift in load favours no way
            figures[way].append(once(extra))
        print(f"  repetition {rep + 1}/{args.reps}", file=sys.stderr, flush=True)
    print(f"{'launch ->':<22} {'banner [s]':<24} {'CPU by then [s]':<24} {'RSS [MB]':<24} goal")
    for way, runs in figures.items():
        walls, cpus, rss = [r[0] for r in runs], [r[1] for r in runs], [r[2] for r in runs]
        met = "met" if statistics.median(walls) <= GOAL_S else "NOT met"
        goal = f"<= {GOAL_S:g} s: {met}" if way in GOALS else ""
        if way == "--page-process":
            met = "met" if statistics.median(rss) <= GOAL_MB else "NOT met"
            goal += f"; both <= {GOAL_MB:g} MB: {met}"
        rss_text = f"{statistics.median(rss):.0f} ({min(rss):.0f}..{max(rss):.0f})"
        print(f"{way:<22} {spread(walls):<24} {spread(cpus):<24} {rss_text:<24} {goal}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
