"""Does recording or watching slow the command path? And how true to time is a replay?

Usage: ``python benchmarks/record_bench.py [--reps N] [--quick] [--no-pin]``.

Launches ``python -m c2rviz --no-viewer --port 0 --record-dir TMP`` and measures, in
turns within each repetition (so a slow spell of the machine falls on every mode):

- ``plain``: nothing records or watches;
- ``recording``: ``record NAME`` runs (every state goes to the recorder; at most one
  frame per 1/hz is written);
- ``watched``: one client is in ``watch 1000`` and reads its stream.

For each: pipelined throughput (one client, ``joints`` lines sent at once) and
request/reply round trips (p50, p99), the same clients as ``benchmarks/run.py``.

Then a replay: a move of a few seconds in ``motion on`` is recorded, played back with
``c2rviz-play`` while a watcher takes every state, and the lag of the last moving state
behind its recorded time is printed (per second recorded). Figures only: nothing here
passes or fails.
"""

from __future__ import annotations

import argparse
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

import loadgen
from processes import HOST, ROOT, Launched, launch, pin_cpus

N_JOINTS = 7  # motoman_sia20d
MODES = ("plain", "recording", "watched")


class Control:
    """A line client for set-up commands."""

    def __init__(self, address: tuple[str, int]) -> None:
        self.sock = socket.create_connection(address, timeout=60)
        self.file = self.sock.makefile("rb")

    def ask(self, line: str) -> str:
        self.sock.sendall(line.encode() + b"\n")
        reply = self.file.readline().decode().rstrip("\n")
        if not reply.startswith("ok"):
            raise RuntimeError(f"{line!r}: {reply}")
        return reply

    def close(self) -> None:
        self.file.close()
        self.sock.close()


class Watcher:
    """A client in ``watch HZ`` whose thread reads (and keeps) every line."""

    def __init__(self, address: tuple[str, int], hz: float) -> None:
        self.sock = socket.create_connection(address, timeout=60)
        self.file = self.sock.makefile("rb")
        self.sock.sendall(f"watch {hz}\n".encode())
        if self.file.readline() != b"ok\n":
            raise RuntimeError("watch refused")
        self.lines: list[str] = []
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        for raw in self.file:
            self.lines.append(raw.decode().rstrip("\n"))

    def close(self) -> None:
        self.sock.shutdown(socket.SHUT_RDWR)
        self.thread.join(timeout=10)
        self.file.close()
        self.sock.close()


def percentile(values: Sequence[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


Figures = tuple[float, float, float, float]


def measure(proc: Launched, pipelined: int, round_trips: int) -> Figures:
    """Commands/s pipelined, the server's CPU per command then [us]; request/reply p50 and
    p99 [us]."""
    lines = loadgen.joints_lines(N_JOINTS, 1000)
    cpu = proc.cpu_s()
    rate = loadgen.pipelined(proc.address, lines, pipelined // len(lines))
    cpu_us = (proc.cpu_s() - cpu) / pipelined * 1e6
    times = loadgen.request_reply(proc.address, lines, round_trips)
    return rate, cpu_us, percentile(times, 50) * 1e6, percentile(times, 99) * 1e6


def one_mode(
    proc: Launched, control: Control, mode: str, rep: int, plan: argparse.Namespace
) -> Figures:
    watcher = Watcher(proc.address, 1000) if mode == "watched" else None
    if mode == "recording":
        control.ask(f"record bench{rep} overwrite")
    try:
        return measure(proc, plan.pipelined, plan.round_trips)
    finally:
        if mode == "recording":
            control.ask("record stop")
        if watcher is not None:
            watcher.close()


def replay_lag(proc: Launched, control: Control, folder: Path) -> tuple[float, float, int]:
    """Record a move, replay it while watching; return (recorded s, lag of the replay's
    last moving state behind its recorded time [s], frames)."""
    control.ask("degrees")
    control.ask("motion on")
    control.ask("speed 60")
    control.ask("record lag overwrite")
    control.ask("j 90,45,0,-30,0,60,0")
    control.ask("j -45,20,30,0,0,-30,0")
    control.ask("record stop")
    control.ask("home")
    rows = (folder / "lag.csv").read_text().splitlines()[1:]
    frames = [(float(r.split(",")[0]), r.split(",")[1 : 1 + N_JOINTS]) for r in rows]
    watcher = Watcher(proc.address, 1000)
    played = subprocess.run(
        [
            sys.executable,
            "-m",
            "c2rviz.clients.player",
            str(folder / "lag.txt"),
            "--port",
            str(proc.port),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    if played.returncode != 0:
        raise RuntimeError(played.stderr)
    time.sleep(0.2)
    watcher.close()
    seen = {}
    for line in watcher.lines:
        if line.startswith("state "):
            _, t, values = line.split(" ")
            seen.setdefault(values, float(t))  # the first time each state was seen
    home = frames[0][1]
    first = next(k for k, (_, q) in enumerate(frames) if q != home)
    key = [",".join(f"{float(v):.10g}" for v in q) for _, q in frames]
    shown = [(seen.get(k), t) for k, (t, _) in zip(key, frames)]
    start = shown[first][0]
    assert start is not None
    lags = [s - start - (t - frames[first][0]) for s, t in shown[first:] if s is not None]
    return frames[-1][0] - frames[first][0], lags[-1], len(frames)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="one short repetition")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the processes")
    plan = parser.parse_args(argv)
    plan.pipelined, plan.round_trips = (10_000, 500) if plan.quick else (100_000, 10_000)
    reps = 1 if plan.quick else plan.reps
    print(f"c2rviz record/watch overhead: {pin_cpus(not plan.no_pin)}", flush=True)
    results: dict[str, list[Figures]] = {mode: [] for mode in MODES}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        argv_ = [sys.executable, "-m", "c2rviz", "--port", "0", "--no-viewer"]
        proc = launch([*argv_, "--record-dir", str(folder)], viewer=False)
        control = Control(proc.address)
        try:
            for rep in range(reps):
                order = MODES[rep % 3 :] + MODES[: rep % 3]
                for mode in order:
                    results[mode].append(one_mode(proc, control, mode, rep, plan))
                print(f"  repetition {rep + 1}/{reps} done", flush=True)
            recorded_s, lag_s, frames = replay_lag(proc, control, folder)
        finally:
            control.close()
            proc.stop()
    print(
        f"\n{'mode':<10} {'pipelined cmd/s':>16} {'vs plain':>9} {'CPU us/cmd':>11} "
        f"{'p50 us':>8} {'p99 us':>8} {'p99 vs plain':>13}"
    )

    def median(mode: str, k: int) -> float:
        return statistics.median(r[k] for r in results[mode])

    for mode in MODES:
        rate, cpu, p50, p99 = (median(mode, k) for k in range(4))
        print(
            f"{mode:<10} {rate:>16,.0f} {rate / median('plain', 0):>9.1%} {cpu:>11.2f} "
            f"{p50:>8.1f} {p99:>8.1f} {p99 / median('plain', 3):>13.1%}"
        )
    print(
        f"\nreplay: {frames} frames over {recorded_s:.2f} s recorded; the last moving state "
        f"came {lag_s * 1000:.0f} ms after its recorded time "
        f"({lag_s / recorded_s * 1000:.1f} ms per recorded second)"
    )
    print(f"medians of {reps} repetition(s); HOST {HOST}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
