"""``c2rviz-play BAG`` on a long bag: time to the first ``joints`` line, and the player's memory.

Run: ``python benchmarks/bag_play_bench.py [--quick] [--minutes M] [--keep DIR]``.

A bag like a c2rviz recording of the motoman (``/joint_states`` and ``/tf`` at 100
Hz; 60 minutes, 6 with ``--quick``) is written once. A real server runs in this
process (a thread), with an observer that notes when the first ``joints`` line
arrives. ``c2rviz-play BAG`` is started as a fresh process (interpreter start and
imports included), and the time from its start to that first line is measured:

- ``--duration 60``: the first minute is checked, then played (goal <= 2 s);
- whole: the whole bag is checked first, then played (goal <= 10 s).

The player is stopped once its first line is in. Its memory: the peak RSS
(``/proc/PID/status`` VmHWM, read as it runs) of ``c2rviz-play BAG
--to-commands OUT``, which reads, checks and writes every sample as a play does,
over the first minute and over the whole bag (flat: the same peak however long),
and while it plays ``--duration`` of the bag to the server at ``--rate 100`` (RSS
sampled every 0.5 s: flat over the play). Figures only: nothing passes or fails.
"""

from __future__ import annotations

import argparse
import asyncio
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from bag_bench import load, long_bag  # noqa: E402

from c2rviz.session import Services  # noqa: E402
from c2rviz.transports.tcp_server import CommandServer  # noqa: E402
from c2rviz.world.observer import Observer  # noqa: E402
from c2rviz.world.world import World  # noqa: E402

__all__ = ["main"]


class FirstJoints(Observer):
    """Notes the wall time [s, perf_counter] of the first ``joints`` line (and counts them)."""

    def __init__(self) -> None:
        self.first: float | None = None
        self.count = 0
        self.seen = threading.Event()

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        if line.startswith("joints "):
            self.count += 1
            if self.first is None:
                self.first = time.perf_counter()
                self.seen.set()


class Server:
    """A real command server of the motoman on its own loop and thread."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.world = World(load())
        self.server = CommandServer(Services(self.world))
        threading.Thread(target=self.loop.run_forever, daemon=True).start()
        start = asyncio.run_coroutine_threadsafe(self.server.start("127.0.0.1", 0), self.loop)
        self.port = start.result(timeout=60)[1]

    def watch(self) -> FirstJoints:
        watcher = FirstJoints()
        self.loop.call_soon_threadsafe(self.world.add_observers, [watcher])
        return watcher

    def stop(self) -> None:
        asyncio.run_coroutine_threadsafe(self.server.stop(), self.loop).result(timeout=60)
        self.loop.call_soon_threadsafe(self.loop.stop)


def player(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "c2rviz.clients.player", *args],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def rss_mb(pid: int, key: str = "VmRSS") -> float:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


def first_line(server: Server, bag: Path, duration: str | None) -> tuple[float, float]:
    """Seconds from the player's start to the first ``joints`` line, and its RSS then."""
    watcher = server.watch()
    flags = ["--port", str(server.port)] + (["--duration", duration] if duration else [])
    start = time.perf_counter()
    proc = player(str(bag), *flags)
    watcher.seen.wait(timeout=120)
    rss = rss_mb(proc.pid)
    proc.kill()
    proc.communicate()
    assert watcher.first is not None, "no joints line came"
    return watcher.first - start, rss


def peak_converting(bag: Path, out: Path, duration: str | None) -> tuple[float, float]:
    """(wall s, peak RSS MB) of ``--to-commands`` over the span."""
    flags = ["--joints", ",".join(load().joint_names), "--to-commands", str(out)]
    start = time.perf_counter()
    proc = player(str(bag), *flags, *(["--duration", duration] if duration else []))
    peak = 0.0
    while proc.poll() is None:
        peak = max(peak, rss_mb(proc.pid, "VmHWM"))
        time.sleep(0.05)
    _, err = proc.communicate()
    if proc.returncode != 0:
        raise RuntimeError(err)
    return time.perf_counter() - start, peak


def playing(server: Server, bag: Path, seconds: float) -> list[float]:
    """RSS [MB] every 0.5 s while the player plays ``seconds`` of the bag at --rate 100."""
    proc = player(str(bag), "--port", str(server.port), "--duration", f"{seconds:g}",
                  "--rate", "100", "--window", "8")  # fmt: skip
    samples = []
    while proc.poll() is None:
        time.sleep(0.5)
        samples.append(rss_mb(proc.pid))
    proc.communicate()
    return [s for s in samples if s > 0]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a 6-minute bag")
    parser.add_argument("--minutes", type=float, help="length of the bag (default 60)")
    parser.add_argument("--keep", type=Path, help="write the bag in this folder and keep it")
    args = parser.parse_args(argv)
    minutes = args.minutes or (6.0 if args.quick else 60.0)
    with tempfile.TemporaryDirectory() as temporary:
        folder = args.keep or Path(temporary)
        folder.mkdir(parents=True, exist_ok=True)
        bag = folder / f"joint_states_{minutes:g}min"
        if not bag.exists():
            long_bag(bag, minutes)
        server = Server()
        try:
            print(f"c2rviz-play {bag.name} (a fresh process each; wall time from its start)")
            print(f"{'span':>8s} {'first joints s':>15s} {'goal':>6s} {'RSS then':>9s}")
            for label, duration, goal in (("60 s", "60", 2.0), ("whole", None, 10.0)):
                seconds, rss = first_line(server, bag, duration)
                print(f"{label:>8s} {seconds:15.2f} {goal:5.0f}s {rss:6.0f} MB")
            print()
            print(f"the player's memory: --to-commands over the span ({bag.name})")
            print(f"{'span':>8s} {'wall s':>7s} {'peak RSS':>9s}")
            out = folder / "out.txt"
            for label, duration in (("60 s", "60"), ("whole", None)):
                wall, peak = peak_converting(bag, out, duration)
                print(f"{label:>8s} {wall:7.1f} {peak:6.0f} MB")
            out.unlink(missing_ok=True)
            seconds = 60.0 if args.quick else 600.0
            rss = playing(server, bag, seconds)
            print(
                f"playing {seconds:g} s of it at --rate 100: RSS {min(rss):.0f}..{max(rss):.0f} "
                f"MB over {len(rss)} samples (first {rss[0]:.0f}, last {rss[-1]:.0f})"
            )
        finally:
            server.stop()
    print("goals: first joints line <= 2 s (--duration 60) and <= 10 s (whole), check "
          "included; memory flat: the whole bag peaks where its first minute does")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
