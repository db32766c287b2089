"""How fast OMPL plans around boxes with the project's collision model, and how good the paths are.

For each arm (the three bundled ones, and example-robot-data's panda when it is
installed) a fixed set of scenes is drawn from a fixed seed: a start and a goal,
collision-free, at most ``--reach`` rad apart on every joint, and a box (15 cm)
where the tool passes halfway along the straight joint path, so that the
straight path is blocked and the planner has to go around (the box above the
floor: its centre at least half its size above the base). Each scene is
planned once with its own seed (``plan_for``: the direct edge, RRT-Connect,
OMPL's shortcutting, the final check at 1 degree / 5 mm of tool travel).

Printed per arm: planning time median and p95 [ms], validity checks per second
(the checks the planner asked for over its whole time, and the raw rate of
``ValidityChecker.is_valid`` on random configurations), the path's length
against the straight joint-space line (median and max of the ratio), the
waypoints, and the scenes with no path in the time limit. Then one table with
the goals: median <= 50 ms, p95 <= 250 ms, >= 20,000 checks/s.

Run: ``python benchmarks/planning_bench.py`` (``--quick``: fewer scenes).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import math
import os
import platform
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.collision import CollisionModel  # noqa: E402
from c2rviz.planning import NoPathFound, ValidityChecker, edge_resolution, plan_for  # noqa: E402
from c2rviz.robot import Robot  # noqa: E402

BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}
PANDA = ("panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp")
BOX_M = 0.15  # [m] edge of the box in the way
GOALS = {"median": 50.0, "p95": 250.0, "rate": 20_000.0}


def panda() -> Robot | None:
    """example-robot-data's panda, or None when that package is not installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for file in dist.files or ():
        if file.parts[-2:] == ("example-robot-data", "package.xml"):
            folder = Path(str(dist.locate_file(file))).parent
            urdf, base, eelink = PANDA
            return Robot.from_urdf(
                folder / "robots" / urdf, base, eelink, package_paths=[folder.parent]
            )
    return None


def load(name: str) -> Robot | None:
    if name == "panda":
        return panda()
    path, base, eelink = BUNDLED[name]
    return Robot.from_urdf(ROOT / path, base, eelink)


@dataclass(frozen=True)
class Scene:
    """A start, a goal and the box between them (its centre in the base frame [m])."""

    start: tuple[float, ...]
    goal: tuple[float, ...]
    box: tuple[float, float, float]


def place_box(model: CollisionModel, centre: Sequence[float]) -> None:
    model.remove_all()
    model.set_object("box", "box", (BOX_M,) * 3, pin.SE3(np.eye(3), np.asarray(centre)))


def scenes(model: CollisionModel, count: int, reach_rad: float, seed: int) -> list[Scene]:
    """``count`` scenes whose straight joint path is blocked by the box, drawn from ``seed``."""
    robot = model.robot
    rng = np.random.default_rng(seed)
    found: list[Scene] = []
    while len(found) < count:
        model.remove_all()
        start = np.array(model.random_free(rng))
        lower, upper = np.array(robot.lower), np.array(robot.upper)
        step = rng.uniform(-reach_rad, reach_rad, robot.n)
        goal = np.clip(start + step, lower, upper)
        box = robot.ee_pose(((start + goal) / 2).tolist()).translation
        if box[2] < BOX_M / 2:  # the box stands on the floor or above it
            continue
        place_box(model, box)
        checker = ValidityChecker(model)
        points = checker.edge_points(start, goal)
        ends_free = checker.is_valid(start) and checker.is_valid(goal)
        if ends_free and checker.first_invalid(points) is not None:
            found.append(Scene(tuple(start), tuple(goal), tuple(box)))
    return found


def raw_rate(checker: ValidityChecker, robot: Robot, configs: int) -> float:
    """``is_valid`` calls per second on random configurations."""
    rng = np.random.default_rng(7)
    qs = [robot.random(rng) for _ in range(configs)]
    began = time.perf_counter()
    for q in qs:
        checker.is_valid(q)
    return configs / (time.perf_counter() - began)


def bench(name: str, robot: Robot, count: int, reach_rad: float, timeout_s: float) -> dict:
    model = CollisionModel(robot)
    times, rates, ratios, corners, states, failed = [], [], [], [], [], 0
    for k, scene in enumerate(scenes(model, count, reach_rad, seed=11)):
        place_box(model, scene.box)
        checker = ValidityChecker(model)
        try:
            path = plan_for(checker, scene.start, scene.goal, timeout_s=timeout_s, seed=k)
        except NoPathFound as exc:
            failed += 1
            times.append(timeout_s)
            print(f"  scene {k}: {exc}")
            continue
        times.append(path.planning_s)
        states.append(path.states_checked)
        rates.append(path.states_checked / path.planning_s)
        straight = float(np.linalg.norm(np.subtract(scene.goal, scene.start)))
        ratios.append(path.length_rad / straight)
        corners.append(len(path.waypoints))
    median = statistics.median(times) * 1e3
    p95 = float(np.percentile(times, 95)) * 1e3
    rate = statistics.median(rates) if rates else 0.0
    raw = raw_rate(ValidityChecker(model), robot, 2000)
    resolution = edge_resolution(robot)
    arms = ", ".join(f"{x:.2f}" for x in resolution.lever_arm)
    print(
        f"{name}: {robot.n} joints, lever arms {arms} m; {len(times)} scenes, "
        f"planning median {median:.1f} ms, p95 {p95:.1f} ms, max {max(times) * 1e3:.1f} ms; "
        f"checks per plan median {statistics.median(states) if states else 0:,.0f}; "
        f"{rate:,.0f} checks/s while planning, {raw:,.0f}/s is_valid on random configurations; "
        f"length / straight median {statistics.median(ratios):.2f}, max {max(ratios):.2f}; "
        f"waypoints median {statistics.median(corners):.0f}, max {max(corners)}; "
        f"no path: {failed}"
    )
    return {"median": median, "p95": p95, "rate": rate, "raw": raw}


def machine() -> str:
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
        f"Python {platform.python_version()}; load average {load}"
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="*", default=[*BUNDLED, "panda"])
    parser.add_argument("--scenes", type=int, default=30, help="scenes per arm")
    parser.add_argument("--reach", type=float, default=1.5, help="most a joint moves [rad]")
    parser.add_argument("--timeout", type=float, default=1.0, help="planning time limit [s]")
    parser.add_argument("--quick", action="store_true", help="5 scenes per arm")
    args = parser.parse_args(argv)
    count = 5 if args.quick else args.scenes
    print(machine())
    rows = []
    for name in args.robots:
        if name not in BUNDLED and name != "panda":
            print(f"{name}: unknown (choose from {', '.join([*BUNDLED, 'panda'])}); skipped")
            continue
        robot = load(name)
        if robot is None:
            print(f"{name}: example-robot-data is not installed; skipped")
            continue
        rows.append((name, bench(name, robot, count, args.reach, args.timeout)))
    print()
    print("| arm | median ms | p95 ms | checks/s planning | is_valid/s | goals met |")
    print("|---|---|---|---|---|---|")
    for name, r in rows:
        met = (
            r["median"] <= GOALS["median"]
            and r["p95"] <= GOALS["p95"]
            and min(r["rate"], r["raw"]) >= GOALS["rate"]
        )
        print(
            f"| {name} | {r['median']:.1f} | {r['p95']:.1f} | {r['rate']:,.0f} | "
            f"{r['raw']:,.0f} | {'yes' if met else 'NO'} |"
        )
    print(
        f"goals: median <= {GOALS['median']:.0f} ms, p95 <= {GOALS['p95']:.0f} ms, "
        f">= {GOALS['rate']:,.0f} checks/s"
    )
    return 0 if math.isfinite(sum(r["median"] for _, r in rows)) else 1


if __name__ == "__main__":
    sys.exit(main())
