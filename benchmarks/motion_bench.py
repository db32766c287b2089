"""What motion costs on the event loop: planning a move and sampling it.

Run: ``PYTHONPATH=. python benchmarks/motion_bench.py [--robot NAME] [--quick]``.
Prints one row per operation: the median over repeats of the mean time per
call [us]. The 7-joint motoman is the default; each operation is timed on
fresh states drawn at random within the limits (seeded), so no figure comes
from one lucky case.

Rows:
    ruckig calculate        ruckig alone: a 7-joint move from rest (the floor)
    move_to from rest       plan + exact position-range check
    move_to preempting      the same from a moving state (a new target mid-move)
    follow (100 Hz stream)  one setpoint of a fast sine, replanned from the moving state
    stop mid-move           brake to rest
    sample mid-move         one frame: Trajectory.at_time and tuples
    sample at rest          one frame after arrival
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from importlib.metadata import version
from pathlib import Path

import numpy as np
import ruckig

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.motion.limits import motion_limits  # noqa: E402
from c2rviz.motion.planner import Motion  # noqa: E402
from c2rviz.robot.model import Robot  # noqa: E402

ROBOTS = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}


def per_call_us(
    setup: Callable[[int], Callable[[], object]], calls: int, repeats: int
) -> tuple[float, float]:
    """Median and best, over ``repeats``, of the mean time [us] of one call.

    ``setup(i)`` prepares call ``i`` (untimed) and returns it; each call is timed
    alone, right after its setup, as the event loop would make it.
    """
    figures = []
    clock = time.perf_counter
    for r in range(repeats):
        total = 0.0
        for i in range(calls):
            call = setup(r * calls + i)
            start = clock()
            call()
            total += clock() - start
        figures.append(total / calls * 1e6)
    return statistics.median(figures), min(figures)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(ROBOTS), default="motoman_sia20d")
    parser.add_argument("--quick", action="store_true", help="few repeats (a smoke run)")
    args = parser.parse_args(argv)
    calls, repeats = (50, 3) if args.quick else (500, 9)

    path, base, eelink = ROBOTS[args.robot]
    robot = Robot.from_urdf(ROOT / path, base, eelink)
    limits = motion_limits(robot)
    rng = np.random.default_rng(1)
    pairs = [(robot.random(rng), robot.random(rng)) for _ in range(calls * repeats + 1)]
    n = robot.n

    otg, inp, trajectory = ruckig.Ruckig(n), ruckig.InputParameter(n), ruckig.Trajectory(n)
    inp.max_velocity = list(limits.velocity)
    inp.max_acceleration = list(limits.acceleration)
    inp.max_jerk = list(limits.jerk)
    inp.synchronization = ruckig.Synchronization.Phase
    motion = Motion(limits, pairs[0][0])  # one per robot, as the server would keep it

    def ruckig_alone(i: int) -> Callable[[], object]:
        inp.current_position, inp.target_position = pairs[i]
        return lambda: otg.calculate(inp, trajectory)

    def from_rest(i: int) -> Callable[[], object]:
        motion.jump(pairs[i][0], 0.0)
        return lambda: motion.move_to(pairs[i][1], 0.0)

    def moving(i: int) -> float:
        motion.jump(pairs[i][0], 0.0)
        return 0.4 * motion.move_to(pairs[i][1], 0.0)

    def preempting(i: int) -> Callable[[], object]:
        t = moving(i)
        return lambda: motion.move_to(pairs[i + 1][1], t)

    def stopping(i: int) -> Callable[[], object]:
        t = moving(i)
        return lambda: motion.stop(t)

    def sampling(i: int) -> Callable[[], object]:
        t = moving(i)
        return lambda: motion.sample(t)

    def at_rest(i: int) -> Callable[[], object]:
        motion.jump(pairs[i][0], 0.0)
        return lambda: motion.sample(1.0)

    bounds = list(zip(robot.lower, robot.upper))
    centre = np.array([0.0 if math.isinf(lo) else (lo + hi) / 2 for lo, hi in bounds])
    amplitude = 0.25 * np.array([2.0 if math.isinf(lo) else hi - lo for lo, hi in bounds])
    stream = Motion(limits, centre.tolist())
    ticks = iter(range(10**9))

    def following(i: int) -> Callable[[], object]:
        k = next(ticks)
        setpoint = (centre + amplitude * math.sin(6.0 * k * 0.01)).tolist()
        return lambda: stream.follow(setpoint, k * 0.01)

    rows = [
        ("ruckig calculate", ruckig_alone),
        ("move_to from rest", from_rest),
        ("move_to preempting", preempting),
        ("follow (100 Hz stream)", following),
        ("stop mid-move", stopping),
        ("sample mid-move", sampling),
        ("sample at rest", at_rest),
    ]
    print(f"robot: {args.robot} ({n} joints), ruckig {version('ruckig')}")
    print(f"{calls} calls x {repeats} repeats; us per call")
    print("| operation | median us | best us |")
    print("|---|---|---|")
    for label, setup in rows:
        median, best = per_call_us(setup, calls, repeats)
        print(f"| {label} | {median:.1f} | {best:.1f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
