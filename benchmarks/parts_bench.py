"""What parts cost the command path: one ``joints`` line's world update with no part
held, and with a part held among 21 (the held part follows the gripper's link by
forward kinematics every time the arm is shown); a grasp (the jaws from the finger
shapes, the rule over every part) and a release (the drop search over every object
and part). The bundled fanuc, CPU time of this process, median of ``--repeat`` runs.

Run: ``python benchmarks/parts_bench.py [--repeat N]``. Goal: carrying a part adds
under 50 us to a shown pose (a flood of ``joints`` lines stays flood-fast). Figures
only: nothing here passes or fails.
"""

from __future__ import annotations

import argparse
import asyncio
import statistics
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from c2rviz.robot.model import Robot
from c2rviz.world.world import World

ROOT = Path(__file__).resolve().parent.parent
PICK = (0, 0.3, -0.3, 0, -0.9707963, 0)  # the fanuc pointing down (docs/parts.md)
LINES = 5000


def _at(x: float, y: float, z: float) -> pin.SE3:
    return pin.SE3(np.eye(3), np.array([x, y, z]))


async def _once() -> tuple[float, float, float, float]:
    robot = Robot.from_urdf(ROOT / "robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6")
    world = World(robot)
    world.set_q(PICK)
    world.state().opening = 1.0

    def flood() -> float:
        start = time.process_time()
        for k in range(LINES):
            world.set_q((k * 1e-5, *PICK[1:]))
        return (time.process_time() - start) / LINES

    bare = flood()
    world.set_q(PICK)
    world.parts.add("p", "box", (0.03, 0.03, 0.03), _at(0.4438, 0, 0.339))
    for i in range(20):
        world.parts.add(f"q{i}", "sphere", (0.02,), _at(1 + 0.1 * i, 1, 0.02))
    world.parts._fingers(world.default)  # the finger shapes, read once per robot
    start = time.process_time()
    world.parts.close(world.default, 1.0, 0.0)
    grasp = time.process_time() - start
    held = flood()
    start = time.process_time()
    world.parts.release(world.default)
    release = time.process_time() - start
    world.close()
    return bare, held, grasp, release


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    runs = [asyncio.run(_once()) for _ in range(args.repeat)]
    bare, held, grasp, release = (statistics.median(column) for column in zip(*runs))
    print(f"a shown pose, no part held:      {bare * 1e6:8.1f} us")
    print(
        f"a shown pose, a part held (21):  {held * 1e6:8.1f} us   (goal: < {bare * 1e6 + 50:.0f})"
    )
    print(f"a grasp (21 parts):              {grasp * 1e3:8.2f} ms")
    print(f"a release (drop search):         {release * 1e3:8.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
