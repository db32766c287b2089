"""How long the program takes to start: launch until its banner (every door open, the page
served), and the CPU it spent to get there.

Usage: ``python benchmarks/start_bench.py [--reps 10] [--no-pin]``.

Each repetition launches ``python -m c2rviz`` in three ways, in turn: as a user starts it
(the page, CRCL and rosbridge, every port free), ``--no-viewer``, and the command port
alone (``--no-viewer --no-crcl --no-rosbridge``). A launch counts until the line
``commands on ...`` (and the viewer's URL, when there is a viewer): the program prints its
banner only once every door is open. Printed: the median and spread of the wall time and
of the process's CPU time at that moment, beside the goal (issue 30: start <= 1 s).
"""

from __future__ import annotations

import argparse
import statistics
import sys
from collections.abc import Sequence

from processes import launch, pin_cpus
from report import machine

GOAL_S = 1.0
WAYS = {
    "as a user starts it": [],
    "--no-viewer": ["--no-viewer"],
    "command port alone": ["--no-viewer", "--no-crcl", "--no-rosbridge"],
}


def once(extra: list[str]) -> tuple[float, float]:
    """(launch -> banner [s], CPU time of the process by then [s])."""
    argv = [sys.executable, "-m", "c2rviz", "--port", "0", "--crcl-port", "0"]
    argv += ["--rosbridge-port", "0", "--viser-port", "0", *extra]
    proc = launch(argv, viewer="--no-viewer" not in extra)
    try:
        cpu = proc.cpu_s()
        ready = max(proc.port_open_s or 0.0, proc.viewer_s or 0.0)
        return ready, cpu
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
    figures: dict[str, list[tuple[float, float]]] = {way: [] for way in WAYS}
    for rep in range(max(1, args.reps)):
        for way, extra in WAYS.items():  # in turn, so a drift in load favours no way
            figures[way].append(once(extra))
        print(f"  repetition {rep + 1}/{args.reps}", file=sys.stderr, flush=True)
    print(f"{'launch ->':<22} {'banner [s]':<24} {'CPU by then [s]':<24} goal")
    for way, runs in figures.items():
        walls, cpus = [w for w, _ in runs], [c for _, c in runs]
        met = "met" if statistics.median(walls) <= GOAL_S else "NOT met"
        goal = f"<= {GOAL_S:g} s: {met}" if way == "as a user starts it" else ""
        print(f"{way:<22} {spread(walls):<24} {spread(cpus):<24} {goal}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
