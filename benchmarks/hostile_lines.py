"""How long the parser takes to refuse a hostile line, and how that grows with its length.

A regular expression that can split a run of characters two ways backtracks
quadratically: one 8 KiB line once held the event loop for 3 s. Each hostile
line here (the same shapes as ``tests/test_parser.py``'s ``HOSTILE``) is timed
at 2 KiB and at 8 KiB, best of ``--reps`` runs each. Linear parsing makes the
8 KiB line about 4x slower than the 2 KiB one; quadratic, about 16x. Figures
only: nothing here passes or fails (the tests check only that each line is
refused with our error; a time cannot be judged on a busy machine).

Usage: ``python benchmarks/hostile_lines.py [--quick] [--reps N]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from c2rviz.errors import C2rvizError  # noqa: E402
from c2rviz.protocol.grammar import parse_line  # noqa: E402

__all__ = ["HOSTILE", "main", "seconds_to_refuse"]


def _late_duplicate(size: int) -> str:
    count = size // 5  # indices and values take about 5 bytes per joint
    indices = ",".join(map(str, range(1, count))) + ",1"
    return f"move {indices} " + ",".join(["0"] * count)


HOSTILE: dict[str, Callable[[int], str]] = {
    "digits-x": lambda size: "joints " + "1" * size + "x",
    "digits-e": lambda size: "sleep " + "1" * size + "e",
    "digits-dot-x": lambda size: "move 0 " + "1" * size + ".x",
    "dots": lambda size: "joints " + "1." * (size // 2),
    "late-duplicate": _late_duplicate,
    "unknown-verb-spaced": lambda size: "fly" + " a" * (size // 2),
    "almost-http": lambda size: "fly" + " " * size + "HTTP/1.1x",
}
"""Name -> a hostile line of about ``size`` bytes."""


def seconds_to_refuse(line: str, reps: int) -> float:
    """Best of ``reps`` times [s] for ``parse_line`` to refuse ``line``."""
    best = float("inf")
    for _ in range(reps):
        start = time.perf_counter()
        try:
            parse_line(line)
        except C2rvizError:
            pass
        else:
            raise AssertionError(f"not refused: {line[:40]!r}...")
        best = min(best, time.perf_counter() - start)
    return best


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=50, help="runs per line (best is kept)")
    parser.add_argument("--quick", action="store_true", help="3 runs per line")
    args = parser.parse_args(argv)
    reps = 3 if args.quick else args.reps
    print("| line | 2 KiB (ms) | 8 KiB (ms) | ratio (linear ~4, quadratic ~16) |")
    print("|---|---|---|---|")
    for name, build in HOSTILE.items():
        short = seconds_to_refuse(build(2048), reps)
        long = seconds_to_refuse(build(8192), reps)
        print(f"| {name} | {short * 1e3:.3f} | {long * 1e3:.3f} | {long / short:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
