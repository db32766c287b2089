"""A controller's suite across cores: 40 tests of the pytest plugin with 1 and 2 workers.

Writes a suite of ``--tests`` tests (default 40, in files of 10) into a temporary folder,
each as a user writes one: a fresh ``c2rviz_server`` (the plugin's; free ports, its run
recorded), a move on the real clock (``motion on``), a check of where the arm is, home.
Then runs it with pytest-xdist, ``python -m pytest -n 1`` and ``-n 2`` (alternating, the
best of ``--repeat`` runs each), and prints the wall time of each and their ratio beside
the goal (2 workers >= 1.6x as fast as 1). Figures only: nothing here passes or fails.

Run: ``python benchmarks/plugin_xdist.py`` (``--quick``: 4 tests, one run each;
``--smoke``: 2 tests, one a worker, one run each: the test suite's run).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from report import machine

ROOT = Path(__file__).resolve().parent.parent
GOAL_RATIO = 1.6
PER_FILE = 10
TEST = """

@pytest.mark.c2rviz(motion="on", speed=SPEED)
def test_move_K(c2rviz):
    target = [0.05 * (K % 5 + 1), 0.1, 0.0, -0.1, 0.0, 0.1, 0.0]
    c2rviz.joints(target)
    assert c2rviz.where() == pytest.approx(target, abs=1e-9)
    c2rviz.home()
    assert c2rviz.where() == (0.0,) * 7
"""


def write_suite(folder: Path, tests: int, speed: int) -> None:
    """``tests`` plugin tests in ``folder``, ``PER_FILE`` to a file, and a pytest.ini."""
    (folder / "pytest.ini").write_text("[pytest]\nfilterwarnings = error\n")
    for first in range(0, tests, PER_FILE):
        body = "import pytest\n" + "".join(
            TEST.replace("SPEED", str(speed)).replace("K", str(k))
            for k in range(first, min(first + PER_FILE, tests))
        )
        (folder / f"test_suite_{first // PER_FILE}.py").write_text(body)


def run(folder: Path, workers: int, tests: int) -> float:
    """The wall time [s] of ``pytest -n WORKERS`` on the suite; it must pass every test."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # this tree's c2rviz and its plugin
    for name in ("PYTEST_ADDOPTS", "PYTEST_XDIST_WORKER", "PYTEST_XDIST_WORKER_COUNT"):
        env.pop(name, None)
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", str(workers)],
        cwd=folder,
        capture_output=True,
        text=True,
        env=env,
        timeout=1800,
        check=False,
    )
    took = time.perf_counter() - start
    if done.returncode != 0 or f"{tests} passed" not in done.stdout:
        raise SystemExit(f"plugin_xdist: the suite failed with -n {workers}:\n{done.stdout}")
    return took


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tests", type=int, default=40, help="tests in the suite")
    parser.add_argument("--repeat", type=int, default=2, help="runs per worker count")
    parser.add_argument("--speed", type=int, default=100, help="the moves' speed [%%]")
    parser.add_argument("--quick", action="store_true", help="4 tests, one run each")
    parser.add_argument("--smoke", action="store_true", help="2 tests, one run each")
    args = parser.parse_args(argv)
    tests, repeat = (2, 1) if args.smoke else (4, 1) if args.quick else (args.tests, args.repeat)
    print(machine())
    with tempfile.TemporaryDirectory(prefix="c2rviz-plugin-xdist-") as folder:
        write_suite(Path(folder), tests, args.speed)
        walls: dict[int, list[float]] = {1: [], 2: []}
        for _ in range(repeat):
            for workers in walls:
                walls[workers].append(run(Path(folder), workers, tests))
    one, two = min(walls[1]), min(walls[2])
    ratio = one / two
    print("| row | unit | figure | goal | met |\n|---|---|---|---|---|")
    print(f"| {tests} plugin tests, pytest -n 1 | s | {one:.1f} |  |  |")
    print(f"| {tests} plugin tests, pytest -n 2 | s | {two:.1f} |  |  |")
    met = "yes" if ratio >= GOAL_RATIO else "no"
    print(f"| 2 workers vs 1 | x | {ratio:.2f} | >= {GOAL_RATIO} | {met} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
