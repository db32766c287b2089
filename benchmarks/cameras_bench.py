"""What a logical camera's look costs: ``see`` over 100 parts in view, with 0, 10 and 100
workcell objects to test each line of sight against (boxes, spheres and cylinders). CPU
time of this process, median of ``--repeat`` runs of ``--looks`` looks each.

Run: ``python benchmarks/cameras_bench.py [--repeat N] [--looks N]``. Goal: a look with
100 parts and 100 objects under 20 ms (a 10 Hz camera then costs under a fifth of the
loop). Figures only: nothing here passes or fails.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Sequence

import numpy as np

from c2rviz.robot.frames import pose_se3
from c2rviz.world.cameras import Camera, Occluder, PartLike, see

GOAL_MS = 20.0


def _scene() -> tuple[Camera, list[PartLike], list[Occluder]]:
    camera = Camera("c", pose_se3((0, 0, 1, 0, math.pi / 2, 0)), math.pi / 2, math.pi / 2, 3.0)
    rng = np.random.default_rng(1)
    parts: list[PartLike] = [
        (f"p{i}", "box", pose_se3((*rng.uniform(-0.5, 0.5, 2), 0.02, 0, 0, 0))) for i in range(100)
    ]
    shapes = [("box", (0.05, 0.05, 0.05)), ("sphere", (0.02,)), ("cylinder", (0.02, 0.1))]
    occluders: list[Occluder] = [
        (f"o{i}", *shapes[i % 3], pose_se3((*rng.uniform(-0.5, 0.5, 2), 0.5, 0, 0, 0)))
        for i in range(100)
    ]
    return camera, parts, occluders


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--looks", type=int, default=20)
    args = parser.parse_args(argv)
    camera, parts, occluders = _scene()
    for count in (0, 10, 100):
        runs = []
        for _ in range(args.repeat):
            start = time.process_time()
            for _ in range(args.looks):
                seen = see(camera, parts, occluders[:count], 0.0)
            runs.append((time.process_time() - start) / args.looks)
        ms = statistics.median(runs) * 1e3
        goal = f"   (goal: < {GOAL_MS:g})" if count == 100 else ""
        print(f"a look, 100 parts, {count:3d} objects: {ms:7.2f} ms, {len(seen)} seen{goal}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
