"""How long collision checks take: at load, per configuration, and along a guarded move.

For each robot it prints:

- load: building the collision geometry (URDF -> Pinocchio + coal), and the
  whole model with its self-collision pairs chosen (home + ``--samples`` random
  configurations; the draws stop once no pair can still reach 95 %);
- per configuration: ``colliding(q)`` (every pair) and ``is_free(q)`` (stops at
  the first hit) over random configurations within the limits, with 0, 3, 10
  and 100 workcell boxes (a ring of boxes around the robot, some in its reach);
- a guarded move: ``segment`` + ``first_collision`` on a 90 degree move of the
  first joint (91 checks at 1 degree apart), free of collisions so every point
  is checked;
- ``random_free``: one collision-free random configuration (3 boxes).

Then, for a cell of two (the motoman at the origin, the Fanuc 1.5 m along x,
facing it): the same guarded 90 degree move of the motoman checked against the
other robot as it stands (``collision.other_robots.first_hit_between``).

Run: ``python benchmarks/collision_bench.py`` (``--quick`` for fewer repeats,
``--robots ur5 panda`` for example-robot-data arms, when installed).
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

from c2rviz.collision.geometry import robot_geometry  # noqa: E402
from c2rviz.collision.model import DEFAULT_SAMPLES, CollisionModel, segment  # noqa: E402
from c2rviz.collision.other_robots import first_hit_between  # noqa: E402
from c2rviz.robot.catalogue import example_robots  # noqa: E402
from c2rviz.robot.model import Robot  # noqa: E402
from c2rviz.world.world import World  # noqa: E402

BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}


def load(name: str) -> Robot:
    """A bundled robot, or an example-robot-data arm."""
    if name in BUNDLED:
        path, base, eelink = BUNDLED[name]
        return Robot.from_urdf(ROOT / path, base, eelink)
    entry = example_robots()[name]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


def best_of(repeats: int, run: Callable[[], object]) -> float:
    """The quickest of ``repeats`` runs of ``run`` [s]."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def ring(model: CollisionModel, count: int) -> None:
    """``count`` boxes of 0.2 m in a ring of radius 0.8 m at 0.5 m high, around the base."""
    model.remove_all()
    for i in range(count):
        angle = 2 * math.pi * i / count
        xyz = np.array([0.8 * math.cos(angle), 0.8 * math.sin(angle), 0.5])
        model.set_object(f"box{i}", "box", (0.2, 0.2, 0.2), pin.SE3(np.eye(3), xyz))


def per_config(model: CollisionModel, qs: list[list[float]], repeats: int) -> tuple[float, ...]:
    """Microseconds per ``colliding`` and per ``is_free``, and the share colliding."""
    colliding = best_of(repeats, lambda: [model.colliding(q) for q in qs]) / len(qs)
    free = best_of(repeats, lambda: [model.is_free(q) for q in qs]) / len(qs)
    share = sum(1 for q in qs if model.colliding(q)) / len(qs)
    return colliding * 1e6, free * 1e6, share


def bench(name: str, samples: int, configs: int, repeats: int) -> None:
    robot = load(name)
    build = best_of(repeats, lambda: robot_geometry(robot))
    full = best_of(repeats, lambda: CollisionModel(robot, samples=samples))
    model = CollisionModel(robot, samples=samples)
    pairs = model.self_pairs
    print(f"{name}: {robot.n} joints, {len(pairs.checked)} link pairs checked")
    print(
        f"  load: geometry {build * 1e3:.1f} ms; the whole model, pairs chosen with "
        f"{samples} samples, {full * 1e3:.1f} ms (touching at home {len(pairs.at_home)}, "
        f"always touching {len(pairs.always)})"
    )
    rng = np.random.default_rng(0)
    qs = [robot.random(rng) for _ in range(configs)]
    for count in (0, 3, 10, 100):
        ring(model, count)
        colliding, free, share = per_config(model, qs, repeats)
        print(
            f"  {count:3d} objects: colliding {colliding:6.1f} us, is_free {free:6.1f} us "
            f"per configuration ({share:.0%} of random ones collide)"
        )
    ring(model, 3)
    start = [0.0] * robot.n
    end = [math.pi / 2] + [0.0] * (robot.n - 1)
    path_time = best_of(repeats, lambda: model.first_collision(segment(robot, start, end)))
    points = len(segment(robot, start, end))
    hit = model.first_collision(segment(robot, start, end))
    print(
        f"  guarded 90 deg move of {robot.joints[0].name}: {path_time * 1e3:.2f} ms "
        f"for {points} points (first collision: {hit})"
    )
    draw = np.random.default_rng(1)
    rand = best_of(repeats, lambda: model.random_free(draw))
    print(f"  random_free with 3 objects: {rand * 1e6:.0f} us")


def between_robots(repeats: int) -> None:
    """A guarded 90 degree move of one robot of a cell, checked against the other."""
    origin = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, math.pi), np.array([1.5, 0.0, 0.0]))
    world = World(
        {"a": load("motoman_sia20d"), "b": load("fanuc_lrmate200id")}, origins={"b": origin}
    )
    robot = world.state("a").robot
    path = segment(robot, [0.0] * robot.n, [math.pi / 2] + [0.0] * (robot.n - 1))
    model, here = world.collision_model("a"), world.state("a").origin

    def check() -> object:
        return first_hit_between(model, here, world.others("a"), path)

    check()  # build both collision models first
    took = best_of(repeats, check)
    hit = check()
    print(
        f"cell: motoman's guarded 90 deg move against a Fanuc 1.5 m away: "
        f"{took * 1e3:.2f} ms for {len(path)} points (first hit: {hit})"
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="*", default=list(BUNDLED))
    parser.add_argument("--samples", type=int, default=DEFAULT_SAMPLES)
    parser.add_argument("--quick", action="store_true", help="fewer configurations and repeats")
    args = parser.parse_args(argv)
    configs, repeats = (200, 1) if args.quick else (2000, 5)
    for name in args.robots:
        if name not in BUNDLED and name not in example_robots():
            print(f"{name}: not bundled and not an installed example robot; skipped")
            continue
        bench(name, args.samples, configs, repeats)
    between_robots(repeats)
    return 0


if __name__ == "__main__":
    sys.exit(main())
