"""How fast and how often the IK answers, per arm, beside the goals of issue 30.

For each arm, one table:

- ``random``: targets made by forward kinematics of random in-limit
  configurations (fixed seeds), solved from a *random* seed configuration
  (the worst case: restarts are common). Goal: median <= 2 ms, p99 <= 10 ms,
  solved >= 99 %.
- ``near``: the same from a seed near the target's configuration (each joint
  within 0.2 rad: a ``moveto`` from where the arm is). No goal of its own.
- ``point``: position-only targets (``PointTarget``, orientation free) from a
  random seed; the same goal as ``random``.
- ``2 m away``: targets 2 m from the base (20 directions): the time to refuse
  (the reach bound answers before any step). Goal: <= 5 ms, all refused.
- ``movel``: 0.5 m lines (random direction, up to 30 deg of turn) from random
  starts until 10 pass; the planning time of those that pass. Goal: median
  <= 10 ms (n/a on an arm of under 6 joints when no full-pose 0.5 m line
  passes: such an arm holds few poses along a line). ``movel pt`` plans the
  same lines with the orientation free.

Times are wall-clock and CPU (thread) time [ms]; the ``met`` column reads the
CPU figure, the steadier one on a shared machine (wall time there includes
waiting for a core). The arms: the bundled ones and every example-robot-data
arm c2rviz can name with at least 5 joints.

Run: ``python benchmarks/ik_bench.py [--quick] [--robots NAME ...]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from report import machine  # noqa: E402

from c2rviz.errors import C2rvizError  # noqa: E402
from c2rviz.ik import IkSolver, LineBlocked, PointTarget, Target, Unreachable, plan_line  # noqa: E402
from c2rviz.robot.catalogue import example_robots  # noqa: E402
from c2rviz.robot.model import Robot  # noqa: E402

__all__ = ["main"]

BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}
MIN_JOINTS = 5  # an example robot with fewer is not an arm this benchmark covers
SOLVE_GOAL = "p50 <= 2, p99 <= 10 ms, >= 99 %"
REFUSE_GOAL = "<= 5 ms, all refused"
LINE_GOAL = "median <= 10 ms"


def load(name: str) -> Robot:
    if name in BUNDLED:
        path, base, eelink = BUNDLED[name]
        return Robot.from_urdf(ROOT / path, base, eelink)
    entry = example_robots()[name]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


def default_robots() -> list[str]:
    """The bundled arms, then every example-robot-data arm with at least MIN_JOINTS joints."""
    names = list(BUNDLED)
    for name in example_robots():
        if load(name).n >= MIN_JOINTS:
            names.append(name)
    return names


def timed(call: Callable[[], object]) -> tuple[bool, float, float]:
    """(succeeded, wall ms, cpu ms) of one call; a C2rvizError counts as a failure."""
    wall, cpu = time.perf_counter(), time.thread_time()
    try:
        call()
        ok = True
    except C2rvizError:
        ok = False
    return ok, (time.perf_counter() - wall) * 1e3, (time.thread_time() - cpu) * 1e3


def solve_rows(
    ik: IkSolver, count: int, near: bool, point: bool = False
) -> tuple[int, list[float], list[float]]:
    robot = ik.robot
    rng = np.random.default_rng(2024)
    solved, walls, cpus = 0, [], []
    for _ in range(count):
        q_target = np.array(robot.random(rng))
        pose = robot.ee_pose(q_target.tolist())
        target: Target = PointTarget.at(pose.translation) if point else pose
        if near:
            seed = np.clip(q_target + rng.uniform(-0.2, 0.2, robot.n), robot.lower, robot.upper)
        else:
            seed = np.array(robot.random(rng))
        ok, wall, cpu = timed(partial(ik.solve, target, seed.tolist()))
        solved += ok
        walls.append(wall)
        cpus.append(cpu)
    return solved, walls, cpus


def far_rows(ik: IkSolver, count: int) -> tuple[int, list[float], list[float]]:
    """Targets 2 m from the base in ``count`` directions, solved from the rest pose."""
    robot = ik.robot
    rng = np.random.default_rng(3)
    rest = [min(max(0.0, lo), hi) for lo, hi in zip(robot.lower, robot.upper)]
    refused, walls, cpus = 0, [], []
    for _ in range(count):
        direction = rng.normal(size=3)
        far = pin.SE3(np.eye(3), 2.0 * direction / np.linalg.norm(direction))
        ok, wall, cpu = timed(partial(ik.solve, far, rest))
        refused += not ok
        walls.append(wall)
        cpus.append(cpu)
    return refused, walls, cpus


def line_rows(
    ik: IkSolver, wanted: int, tries: int, point: bool = False
) -> tuple[int, int, list[float], list[int]]:
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
        target: Target = PointTarget.at(goal.translation) if point else goal
        cpu = time.thread_time()
        try:
            line = plan_line(ik, q0, target)
        except (LineBlocked, Unreachable):
            continue
        times.append((time.thread_time() - cpu) * 1e3)
        waypoints.append(len(line.waypoints))
        passed += 1
    return passed, tried, times, waypoints


def percentiles(values: Sequence[float]) -> str:
    return f"{np.percentile(values, 50):8.2f} {np.percentile(values, 99):7.2f}"


def mark(met: bool) -> str:
    return "yes" if met else "NO"


def arm_table(name: str, count: int, lines_wanted: int) -> bool:
    """Print one arm's table; True when every goal is met."""
    robot = load(name)
    ik = IkSolver(robot)
    print(
        f"\n{name}: {robot.n} joints, reach bound {ik.reach.radius_m():.3f} m from its first joint"
    )
    print(
        f"{'robot':18s} {'case':8s} {'solved':>9s}  {'wall p50':>8s} {'p99 ms':>7s}"
        f"  {'cpu p50':>8s} {'p99 ms':>7s}   {'goal':33s} met"
    )
    all_met = True
    for case, near, point in (("random", False, False), ("near", True, False),
                              ("point", False, True)):  # fmt: skip
        solved, walls, cpus = solve_rows(ik, count, near, point)
        goal, verdict = "", ""
        if not near:
            met = (
                float(np.percentile(cpus, 50)) <= 2.0
                and float(np.percentile(cpus, 99)) <= 10.0
                and solved >= 0.99 * count
            )
            goal, verdict = SOLVE_GOAL, mark(met)
            all_met &= met
        print(
            f"{name:18s} {case:8s} {solved:4d}/{count:<4d}  {percentiles(walls)}"
            f"  {percentiles(cpus)}   {goal:33s} {verdict}"
        )
    far_count = 20
    refused, walls, cpus = far_rows(ik, far_count)
    met = refused == far_count and max(cpus) <= 5.0
    all_met &= met
    what = "refused" if refused == far_count else f"{far_count - refused} SOLVED?"
    print(
        f"{name:18s} {'2 m away':8s} {what:>9s}  {np.median(walls):8.2f} {max(walls):7.2f}"
        f"  {np.median(cpus):8.2f} {max(cpus):7.2f}   {REFUSE_GOAL + ' (p99: max)':33s} "
        f"{mark(met)}"
    )
    for case, point in (("movel", False), ("movel pt", True)):
        passed, tried, times, waypoints = line_rows(ik, lines_wanted, 40 * lines_wanted, point)
        if not times:
            # Under 6 joints an arm holds few poses along a line: no 0.5 m one may pass.
            verdict = "n/a" if point or robot.n < 6 else "NO"
            print(
                f"{name:18s} {case:8s} {passed:4d}/{tried:<4d}  no 0.5 m line passed"
                f"{'':49s}  {'' if point else LINE_GOAL:15s} {'' if point else verdict}"
            )
            all_met &= verdict == "n/a"
            continue
        median = float(np.median(times))
        met = median <= 10.0
        goal, verdict = (LINE_GOAL, mark(met)) if not point else ("", "")
        all_met &= met or point
        print(
            f"{name:18s} {case:8s} {passed:4d}/{tried:<4d}  {median:8.1f} ms median to plan 0.5 m"
            f" ({int(np.median(waypoints))} waypoints; cpu, max {max(times):.1f} ms)"
            f"  {goal:15s} {verdict}"
        )
    return all_met


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="20 targets, 2 lines per robot")
    parser.add_argument("--robots", nargs="+", default=None, help="default: every arm")
    args = parser.parse_args(argv)
    count = 20 if args.quick else 500
    lines_wanted = 2 if args.quick else 10
    print(machine())
    names = args.robots if args.robots is not None else default_robots()
    met = [name for name in names if arm_table(name, count, lines_wanted)]
    print(f"\nevery goal met (or n/a) on {len(met)} of {len(names)} arms", end="")
    missed = [name for name in names if name not in met]
    print(f" (missed on: {', '.join(missed)})" if missed else "")
    return 0


if __name__ == "__main__":
    sys.exit(main())
