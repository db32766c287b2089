"""How fast and how often the IK answers, per robot; and what a 0.5 m straight line costs.

For each robot: targets made by forward kinematics of random in-limit
configurations (fixed seeds), solved

- from a *random* seed configuration (the worst case: restarts are common), and
- from a seed *near* the target's configuration (each joint within 0.2 rad: a
  ``moveto`` from where the arm is), and
- for unreachable targets (2 m away): the time to give up.

Solve times are wall-clock and CPU (thread) time [ms]; on a shared machine the
CPU time is the steadier figure. ``movel`` rows plan 0.5 m lines (random
direction, up to 30 deg of turn) from random starts until 10 lines pass, and
report the planning time of those that pass.

Run: ``python benchmarks/ik_bench.py [--quick] [--robots NAME ...]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.errors import C2rvizError  # noqa: E402
from c2rviz.ik.line import LineBlocked, plan_line  # noqa: E402
from c2rviz.ik.solver import IkSolver, Unreachable  # noqa: E402
from c2rviz.robot.catalogue import example_robots  # noqa: E402
from c2rviz.robot.model import Robot  # noqa: E402

__all__ = ["main"]

BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}
DEFAULT_ROBOTS = [*BUNDLED, "ur5", "panda"]


def load(name: str) -> Robot:
    if name in BUNDLED:
        path, base, eelink = BUNDLED[name]
        return Robot.from_urdf(ROOT / path, base, eelink)
    entry = example_robots()[name]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


def timed(call: Callable[[], object]) -> tuple[bool, float, float]:
    """(succeeded, wall ms, cpu ms) of one call; a C2rvizError counts as a failure."""
    wall, cpu = time.perf_counter(), time.thread_time()
    try:
        call()
        ok = True
    except C2rvizError:
        ok = False
    return ok, (time.perf_counter() - wall) * 1e3, (time.thread_time() - cpu) * 1e3


def solve_rows(ik: IkSolver, count: int, near: bool) -> tuple[int, list[float], list[float]]:
    robot = ik.robot
    rng = np.random.default_rng(2024)
    solved, walls, cpus = 0, [], []
    for _ in range(count):
        q_target = np.array(robot.random(rng))
        target = robot.ee_pose(q_target)
        if near:
            seed = np.clip(q_target + rng.uniform(-0.2, 0.2, robot.n), robot.lower, robot.upper)
        else:
            seed = np.array(robot.random(rng))
        ok, wall, cpu = timed(lambda t=target, s=seed: ik.solve(t, s.tolist()))
        solved += ok
        walls.append(wall)
        cpus.append(cpu)
    return solved, walls, cpus


def line_rows(ik: IkSolver, wanted: int, tries: int) -> tuple[int, int, list[float], list[int]]:
    robot = ik.robot
    rng = np.random.default_rng(7)
    passed = tried = 0
    times: list[float] = []
    waypoints: list[int] = []
    while passed < wanted and tried < tries:
        tried += 1
        q0 = robot.random(rng)
        start = ik.tool_pose(q0)
        direction = rng.normal(size=3)
        turn = rng.normal(size=3)
        goal = pin.SE3(
            start.rotation @ pin.exp3(turn / np.linalg.norm(turn) * rng.uniform(0, math.pi / 6)),
            start.translation + 0.5 * direction / np.linalg.norm(direction),
        )
        wall = time.perf_counter()
        try:
            line = plan_line(ik, q0, goal)
        except (LineBlocked, Unreachable):
            continue
        times.append((time.perf_counter() - wall) * 1e3)
        waypoints.append(len(line.waypoints))
        passed += 1
    return passed, tried, times, waypoints


def percentiles(values: Sequence[float]) -> str:
    return f"{np.percentile(values, 50):6.2f} {np.percentile(values, 99):7.2f}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="20 targets, 2 lines per robot")
    parser.add_argument("--robots", nargs="+", default=DEFAULT_ROBOTS)
    args = parser.parse_args(argv)
    count = 20 if args.quick else 500
    lines_wanted = 2 if args.quick else 10
    print(
        f"{'robot':18s} {'case':8s} {'solved':>9s}  {'wall p50':>8s} {'p99 ms':>7s}"
        f"  {'cpu p50':>7s} {'p99 ms':>7s}"
    )
    for name in args.robots:
        robot = load(name)
        ik = IkSolver(robot)
        for case, near in (("random", False), ("near", True)):
            solved, walls, cpus = solve_rows(ik, count, near)
            print(
                f"{name:18s} {case:8s} {solved:4d}/{count:<4d}  {percentiles(walls)}"
                f"  {percentiles(cpus)}"
            )
        far = pin.SE3(np.eye(3), np.array([2.0, 0.0, 0.5]))
        rest = [min(max(0.0, lo), hi) for lo, hi in zip(robot.lower, robot.upper)]
        ok, wall, cpu = timed(lambda f=far, r=rest, k=ik: k.solve(f, r))
        print(f"{name:18s} {'2 m away':8s} {'refused' if not ok else 'SOLVED?':>9s}  "
              f"{wall:8.2f} {'':7s}  {cpu:7.2f}")  # fmt: skip
        passed, tried, times, waypoints = line_rows(ik, lines_wanted, 40 * lines_wanted)
        if times:
            print(
                f"{name:18s} {'movel':8s} {passed:4d}/{tried:<4d}  {np.median(times):8.1f} ms "
                f"median to plan 0.5 m ({int(np.median(waypoints))} waypoints)"
            )
        else:
            print(f"{name:18s} {'movel':8s} {passed:4d}/{tried:<4d}  no 0.5 m line passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
